// Files meshcast reads or writes whole: meshes, blobs, rays and hits, the
// tables and profiles it writes.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "meshcast/errors.h"

namespace meshcast {

// Whole-file helpers for meshes, blobs, rays and hits: read_file reads a
// regular file and throws InputError naming the path for anything else (a
// directory, a device such as /dev/zero or a pipe is refused before any
// read: it has no size to read up to). write_file writes the pieces in order to a file
// beside `path`, checks every write, the flush and the close, then renames it
// to `path`, so a failed write (a full disk) leaves no partial file under
// that name; an existing path that is not a regular file (/dev/null,
// /dev/full, a pipe) is written in place. Failures throw OutputError naming
// the path and the reason.
struct Bytes {
  const void* data;
  size_t size;
};
// The check read_file makes first, for a reader that must judge the path
// before it reads (read_mesh: kind of file, then extension, then bytes).
void require_regular_file(const std::string& path);
std::vector<uint8_t> read_file(const std::string& path);

// Text output (CSV, plot scripts, profiles): built in memory, then written
// by write_file when commit() is called, so it is checked the same way.
class OutputText : public std::ostringstream {
 public:
  explicit OutputText(std::string path) : path_(std::move(path)) {}
  void commit();

 private:
  std::string path_;
};
void write_file(const std::string& path, std::initializer_list<Bytes> pieces);
// The same for a file made a piece at a time (one too large to hold whole):
// next() returns each piece in turn, then one of size 0. A piece's bytes
// need only live until the next call.
void write_file_pieces(const std::string& path, const std::function<Bytes()>& next);
inline void write_file(const std::string& path, const void* data, size_t size) { write_file(path, {{data, size}}); }

}  // namespace meshcast
