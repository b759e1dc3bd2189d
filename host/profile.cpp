#include "host/profile.h"

#include "layout/message_text.h"

#include <sys/stat.h>

#include <cerrno>
#include <charconv>
#include <fstream>
#include <string_view>
#include <vector>

#include "io/files.h"

namespace meshcast::host {

namespace {

constexpr std::string_view kFirstLine = "meshcast-profile 1";
constexpr std::string_view kAnyVersion = "meshcast-profile ";
// A profile is a few hundred bytes: a longer file is not one, and is not
// read whole (a profile path given a blob by mistake).
constexpr size_t kMaxProfileBytes = 4096;

// A line of the file as an error quotes it (message_text.h).
// Built by appending: gcc 12 warns falsely (-Wrestrict) on "'" + a temporary.
std::string quoted(std::string_view line) {
  std::string out = "'";
  out += shown_text(line, 40);
  out += '\'';
  return out;
}

}  // namespace

SavedProfile read_profile(const std::string& path, const std::string& key) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 && errno == ENOENT) return {};  // none yet: measured and written
  auto unused = [&](const std::string& why, bool replaceable) {
    return SavedProfile{std::nullopt, why, replaceable};
  };
  try {
    require_regular_file(path);  // a folder, a device, a pipe: its message names the path
  } catch (const InputError& e) {
    return unused(e.what(), false);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in.is_open()) return unused(path + ": cannot open the file", false);
  std::string text(kMaxProfileBytes + 1, '\0');
  in.read(text.data(), std::streamsize(text.size()));
  if (in.bad()) return unused(path + ": cannot read the file", false);
  text.resize(size_t(in.gcount()));

  if (text.compare(0, kAnyVersion.size(), kAnyVersion) != 0)
    return unused(path + ": not a meshcast profile (its first line is not '" + std::string(kFirstLine) + "')", false);
  // From here on the file is a profile, if not a usable one: it may be replaced.
  if (text.size() > kMaxProfileBytes)
    return unused(path + ": longer than a profile (over " + std::to_string(kMaxProfileBytes) + " bytes)", true);
  std::vector<std::string_view> lines;
  for (std::string_view rest = text; !rest.empty();) {
    const size_t end = rest.find('\n');
    lines.push_back(rest.substr(0, end));  // a last line without its newline is kept, and refused below
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
  }
  if (lines[0] != kFirstLine)
    return unused(path + ": a profile of another version (" + quoted(lines[0]) + ")", true);
  if (lines.size() != 4)
    return unused(path + ": truncated or damaged (" + std::to_string(lines.size()) + " lines where a profile has 4)", true);
  if (text.back() != '\n') return unused(path + ": truncated (its last line has no end)", true);
  if (lines[1] != key)
    return unused(path + ": measured on another device or blob (" + quoted(lines[1]) + ")", true);
  // A decimal batch size and nothing else: no sign (a "-1" read as an
  // unsigned number would wrap to "never"), no exponent, no NaN, no
  // value past 32 bits.
  const std::string_view number = lines[2];
  uint32_t crossover = 0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), crossover);
  if (number.empty() || error != std::errc() || end != number.data() + number.size())
    return unused(path + ": line 3 " + quoted(number) + " is not a batch size (0 to 4294967295)", true);
  return {crossover, std::string(lines[3]), true};
}

void write_profile(const std::string& path, const std::string& key, uint32_t crossover, const std::string& note) {
  OutputText out(path);
  out << kFirstLine << "\n" << key << "\n" << crossover << "\n" << note << "\n";
  out.commit();
}

}  // namespace meshcast::host
