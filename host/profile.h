// The Automatic backend's saved crossover (CasterOptions::profile): four
// lines of text, "meshcast-profile 1", the key of the device and blob it
// was measured on, the crossover (a batch size; 4294967295: never) and the
// note why() gives. A file that is anything else is never used: the
// crossover is measured again, and written over the file only when the
// file is a meshcast profile (of another device, blob or version, or
// damaged); a path named by mistake (a blob, a folder, a device) is left
// as it is.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

namespace meshcast::host {

struct SavedProfile {
  std::optional<uint32_t> crossover;  // set when the file holds the key's crossover
  // With the crossover, its saved note; without, why the file was not used
  // (naming the path and what is wrong), "" when there is no file.
  std::string note;
  bool replaceable = true;  // whether a measured crossover may be written over the file
};

// Never throws for what the file holds; reads at most a few kilobytes, and
// nothing that is not a regular file (a pipe would block).
SavedProfile read_profile(const std::string& path, const std::string& key);
// OutputError naming the path and the reason.
void write_profile(const std::string& path, const std::string& key, uint32_t crossover, const std::string& note);

}  // namespace meshcast::host
