#include "io/files.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include "meshcast/blob.h"

namespace meshcast {

void require_regular_file(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw InputError(path + ": cannot open the file (" + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) throw InputError(path + ": is a directory, not a file");
  if (!S_ISREG(st.st_mode))
    throw InputError(path + ": not a regular file (a device, pipe or socket has no size to read up to)");
}

std::vector<uint8_t> read_file(const std::string& path) {
  require_regular_file(path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path + ": cannot open the file");
  std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path + ": cannot read the file");
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) throw InputError(path + ": cannot read the file");
  return bytes;
}

void OutputText::commit() {
  const std::string text = str();
  write_file(path_, text.data(), text.size());
}

namespace {

// The mode a new file gets from open(..., 0666): 0666 less the umask, read
// from /proc (umask() itself would change it for every thread a moment).
mode_t new_file_mode() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("Umask:", 0) == 0) return mode_t(0666 & ~std::stoul(line.substr(6), nullptr, 8));
  return 0644;
}

}  // namespace

void write_file(const std::string& path, std::initializer_list<Bytes> pieces) {
  auto piece = pieces.begin();
  write_file_pieces(path, [&] {
    while (piece != pieces.end() && piece->size == 0) ++piece;  // a size of 0 would end the file
    return piece == pieces.end() ? Bytes{nullptr, 0} : *piece++;
  });
}

void write_file_pieces(const std::string& path, const std::function<Bytes()>& next) {
  // Named in the caller's terms: the file it asked for and what failed of
  // writing it (the step, where it is one the caller would know).
  auto failed = [&](const char* what, int err) {
    return OutputError(path + ": cannot write the file (" + (*what ? what + std::string(": ") : "") +
                       std::strerror(err) + ")");
  };
  if (path.empty()) throw OutputError("the path is empty: name the file to write");
  // Written beside its name and renamed over it: a regular file or a new
  // path. In place: a device or pipe (renaming would replace it), a
  // symbolic link (renaming would replace the link, not what it names:
  // /dev/stdout), and an existing file in a folder we may not create in.
  struct stat st;
  const bool exists = ::lstat(path.c_str(), &st) == 0;
  bool in_place = exists && !S_ISREG(st.st_mode);
  const std::string folder = std::filesystem::path(path).parent_path().string();
  std::string temp = (folder.empty() ? std::string(".") : folder) + "/.meshcast-XXXXXX";
  int fd = -1;
  if (!in_place) {
    fd = ::mkostemp(temp.data(), O_CLOEXEC);
    if (fd < 0 && exists && (errno == EACCES || errno == EPERM || errno == EROFS)) in_place = true;
    else if (fd < 0) throw failed("create", errno);
  }
  if (in_place) {
    fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) throw failed("open", errno);
  }
  int err = 0;
  const char* step = "write";
  try {  // next() may throw: the partial file goes
    for (Bytes b = next(); b.size > 0 && !err; b = next()) {
      const char* p = static_cast<const char*>(b.data);
      for (size_t left = b.size; left > 0 && !err;) {
        const ssize_t n = ::write(fd, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) err = n < 0 ? errno : ENOSPC;
        else p += n, left -= size_t(n);
      }
    }
  } catch (...) {
    ::close(fd);
    if (!in_place) ::unlink(temp.c_str());
    throw;
  }
  // A replaced file keeps its mode; a new one gets what open() would give.
  const mode_t mode = exists ? (st.st_mode & 07777) : new_file_mode();
  if (!err && !in_place && ::fchmod(fd, mode) != 0) err = errno, step = "set its permissions";
  if (!err && !in_place && ::fsync(fd) != 0) err = errno, step = "flush";
  if (::close(fd) != 0 && !err) err = errno, step = "close";
  // The file written beside it taking its name is no step the caller took:
  // its failure (the path a folder, say) is told by its reason alone.
  if (!err && !in_place && ::rename(temp.c_str(), path.c_str()) != 0) err = errno, step = "";
  if (err) {
    if (!in_place) ::unlink(temp.c_str());
    throw failed(step, err);
  }
}

std::vector<uint8_t> load_blob(const std::string& path) { return read_file(path); }

void save_blob(const std::string& path, std::span<const uint8_t> blob) { write_file(path, blob.data(), blob.size()); }

MappedBlob::MappedBlob(const std::string& path) {
  require_regular_file(path);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path + ": cannot open the file (" + std::strerror(errno) + ")");
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw InputError(path + ": not a regular file");
  }
  size_ = size_t(st.st_size);
  if (size_ > 0) {  // mmap of 0 bytes fails; an empty span is refused by validation instead
    data_ = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (data_ == MAP_FAILED) {
      const int err = errno;
      ::close(fd);
      data_ = nullptr;
      throw InputError(path + ": cannot map the file (" + std::strerror(err) + ")");
    }
  }
  ::close(fd);  // the mapping keeps the file
}

MappedBlob::~MappedBlob() {
  if (data_) ::munmap(data_, size_);
}

MappedBlob::MappedBlob(MappedBlob&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}

MappedBlob& MappedBlob::operator=(MappedBlob&& other) noexcept {
  if (this != &other) {
    if (data_) ::munmap(data_, size_);
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

}  // namespace meshcast
