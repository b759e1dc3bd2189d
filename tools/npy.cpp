#include "tools/npy.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>

#include "meshcast/errors.h"

namespace meshcast::tools {

namespace {

// What numpy (1.x) reads: at most 32 dimensions (NPY_MAXDIMS), and a header
// of at most 10000 bytes (numpy.load's default max_header_size). A file
// beyond either is refused here too, read or written, rather than made into
// one numpy cannot open.
constexpr size_t kMaxDimensions = 32;
constexpr size_t kMaxHeaderBytes = 10000;

// The header's dictionary, as numpy writes it: {'descr': '<f4',
// 'fortran_order': False, 'shape': (4, 3), }. Parsed as the Python literal
// numpy parses (ast.literal_eval): the three keys, each once, a string, a
// bool and a tuple of integers, and nothing after the closing brace but
// white space. Anything else is refused, naming what is wrong.
struct NpyHeader {
  std::optional<std::string> descr;
  std::optional<bool> fortran_order;
  std::optional<std::vector<uint64_t>> shape;
  std::string shape_text;  // as written, for the messages
};

class HeaderParser {
 public:
  HeaderParser(const std::string& path, const std::string& text) : path_(path), text_(text) {}

  NpyHeader parse() {
    NpyHeader h;
    space();
    expect('{', "does not start with '{' (a dictionary)");
    space();
    while (peek() != '}') {
      const std::string key = string("a key");
      space();
      expect(':', "has no ':' after '" + key + "'");
      space();
      if (key == "descr") {
        if (h.descr) twice(key);
        h.descr = string("the descr value");
      } else if (key == "fortran_order") {
        if (h.fortran_order) twice(key);
        h.fortran_order = boolean(key);
      } else if (key == "shape") {
        if (h.shape) twice(key);
        const size_t from = at_;
        h.shape = tuple();
        h.shape_text = text_.substr(from, at_ - from);
      } else {
        fail("has a key '" + key + "' (numpy's holds descr, fortran_order and shape alone)");
      }
      space();
      if (peek() == ',') {
        ++at_;
        space();
      } else if (peek() != '}') {
        fail("has no ',' or '}' after the value of '" + key + "'");
      }
    }
    ++at_;
    space();
    if (at_ != text_.size()) fail("has more after its closing '}'");
    const char* missing = !h.descr ? "descr" : !h.fortran_order ? "fortran_order" : !h.shape ? "shape" : nullptr;
    if (missing) throw InputError(path_ + ": the .npy header has no '" + missing + "' key");
    return h;
  }

 private:
  char peek() const { return at_ < text_.size() ? text_[at_] : '\0'; }
  void space() {
    while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\t' || text_[at_] == '\n' ||
                                  text_[at_] == '\r' || text_[at_] == '\f'))
      ++at_;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_ + ": the .npy header " + what + " at byte " + std::to_string(at_) +
                     " of its dictionary (numpy.save writes {'descr': '<f4', 'fortran_order': False, "
                     "'shape': (4, 3), })");
  }
  [[noreturn]] void twice(const std::string& key) const { fail("names '" + key + "' twice"); }
  void expect(char c, const std::string& what) {
    if (peek() != c) fail(what);
    ++at_;
  }
  // A quoted string without escapes (numpy's keys and descr have none).
  std::string string(const std::string& what) {
    const char quote = peek();
    if (quote != '\'' && quote != '"') fail("has no quoted string for " + what);
    const size_t end = text_.find(quote, at_ + 1);
    if (end == std::string::npos) fail("has a string that is not closed");
    std::string s = text_.substr(at_ + 1, end - at_ - 1);
    if (s.find_first_of("\\\n") != std::string::npos) fail("has a string with an escape or a line break");
    at_ = end + 1;
    return s;
  }
  bool boolean(const std::string& key) {
    for (const char* word : {"True", "False"}) {
      const size_t n = std::strlen(word);
      const bool more = at_ + n < text_.size() && (std::isalnum(uint8_t(text_[at_ + n])) || text_[at_ + n] == '_');
      if (text_.compare(at_, n, word) == 0 && !more) {
        at_ += n;
        return word[0] == 'T';
      }
    }
    fail("has no True or False for '" + key + "'");
  }
  // A tuple of non-negative decimal integers: (), (4,) or (4, 3) and a
  // trailing comma; (4) is a number, not a tuple.
  std::vector<uint64_t> tuple() {
    expect('(', "has no tuple '(' for 'shape'");
    std::vector<uint64_t> dims;
    bool comma = false;
    space();
    while (peek() != ')') {
      const size_t first = at_;
      uint64_t d = 0;
      while (peek() >= '0' && peek() <= '9') {
        if (d > (uint64_t(1) << 40)) fail("has a dimension beyond 2^40 in 'shape'");
        d = d * 10 + uint64_t(peek() - '0');
        ++at_;
      }
      if (at_ == first) fail("has no dimension (a non-negative integer) in 'shape'");
      if (text_[first] == '0' && at_ - first > 1) fail("has a dimension with a leading zero in 'shape'");
      if (dims.size() == kMaxDimensions)
        throw InputError(path_ + ": a shape of more than " + std::to_string(kMaxDimensions) +
                         " dimensions; numpy reads at most " + std::to_string(kMaxDimensions));
      dims.push_back(d);
      space();
      comma = peek() == ',';
      if (comma) {
        ++at_;
        space();
      } else if (peek() != ')') {
        fail("has no ',' or ')' after a dimension of 'shape'");
      }
    }
    if (dims.size() == 1 && !comma) fail("has a number, not a tuple, for 'shape' (one dimension is written (4,))");
    ++at_;
    return dims;
  }

  const std::string& path_;
  const std::string& text_;
  size_t at_ = 0;
};

std::string shape_string(const std::vector<uint64_t>& shape) {
  std::string dims;
  for (uint64_t d : shape) dims += std::to_string(d) + ", ";
  if (shape.size() > 1) dims.resize(dims.size() - 2);  // (4, 3); a 1-d shape keeps its comma: (4,)
  else if (shape.empty()) dims.clear();
  return "(" + dims + ")";
}

template <class T>
void write_values(const std::string& path, const std::vector<uint64_t>& shape, const std::vector<T>& values,
                  const char* descr) {
  if (shape.size() > kMaxDimensions)
    throw InputError(path + ": an array of " + std::to_string(shape.size()) + " dimensions; numpy reads at most " +
                     std::to_string(kMaxDimensions));
  std::string header = "{'descr': '" + std::string(descr) + "', 'fortran_order': False, 'shape': " +
                       shape_string(shape) + ", }";
  // Magic, version, header length (16 bits in format 1.0, 32 in 2.0: 1.0
  // where the header fits, as numpy.save chooses), header padded with
  // spaces and a newline to a multiple of 64 bytes.
  const auto padded = [&header](size_t preamble) {
    const size_t unpadded = preamble + header.size() + 1;
    return header.size() + (64 - unpadded % 64) % 64 + 1;
  };
  const bool wide = padded(10) > UINT16_MAX;
  const size_t length = padded(wide ? 12 : 10);
  header.resize(length - 1, ' ');
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write(wide ? "\x93NUMPY\x02\x00" : "\x93NUMPY\x01\x00", 8);
  const uint8_t bytes[4] = {uint8_t(length), uint8_t(length >> 8), uint8_t(length >> 16), uint8_t(length >> 24)};
  out.write(reinterpret_cast<const char*>(bytes), wide ? 4 : 2);
  out << header;
  out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(T)));
  if (!out) throw OutputError(path + ": cannot be written");
}

}  // namespace

NpyReals read_npy_reals(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot be opened");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0)
    throw InputError(path + ": not a .npy file (numpy.save writes them)");
  const int major = uint8_t(bytes[6]), minor = uint8_t(bytes[7]);
  size_t length = 0, at = 0;
  if ((major < 1 || major > 3) || minor != 0)
    throw InputError(path + ": .npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                     " (1.0, 2.0 and 3.0 are read)");
  if (major == 1) {
    length = uint8_t(bytes[8]) | size_t(uint8_t(bytes[9])) << 8, at = 10;
  } else {
    if (bytes.size() < 12) throw InputError(path + ": a .npy header cut short");
    for (int k = 0; k < 4; ++k) length |= size_t(uint8_t(bytes[8 + k])) << (8 * k);
    at = 12;
  }
  if (bytes.size() < at + length) throw InputError(path + ": a .npy header cut short");
  if (length > kMaxHeaderBytes)
    throw InputError(path + ": a .npy header of " + std::to_string(length) + " bytes; numpy reads at most " +
                     std::to_string(kMaxHeaderBytes) + " (numpy.load's max_header_size)");
  const std::string text = bytes.substr(at, length);
  const NpyHeader header = HeaderParser(path, text).parse();
  const bool is_double = *header.descr == "<f8", is_float = *header.descr == "<f4";
  if (!is_double && !is_float)
    throw InputError(path + ": dtype '" + *header.descr + "'; float32 or float64 little-endian ('<f4', '<f8') expected");
  if (*header.fortran_order)
    throw InputError(path + ": Fortran order; save a C-ordered array (numpy.ascontiguousarray)");
  const std::string& shape_text = header.shape_text;
  NpyReals out;
  out.shape = *header.shape;
  uint64_t count = 1;
  for (uint64_t d : out.shape) {
    if (d != 0 && count > (uint64_t(1) << 36) / d)
      throw InputError(path + ": shape " + shape_text + " is beyond what is read (2^36 values)");
    count *= d;
  }
  const size_t size = is_double ? 8 : 4, data = at + length;
  if (bytes.size() - data < count * size)
    throw InputError(path + ": " + std::to_string((bytes.size() - data) / size) + " values where shape " + shape_text +
                     " needs " + std::to_string(count));
  out.values.resize(count);
  for (uint64_t i = 0; i < count; ++i) {
    if (is_double) {
      std::memcpy(&out.values[i], bytes.data() + data + 8 * i, 8);
    } else {
      float f;
      std::memcpy(&f, bytes.data() + data + 4 * i, 4);
      out.values[i] = f;
    }
  }
  return out;
}

void write_npy(const std::string& path, const std::vector<uint64_t>& shape, const std::vector<float>& values) {
  write_values(path, shape, values, "<f4");
}
void write_npy(const std::string& path, const std::vector<uint64_t>& shape, const std::vector<uint32_t>& values) {
  write_values(path, shape, values, "<u4");
}

}  // namespace meshcast::tools
