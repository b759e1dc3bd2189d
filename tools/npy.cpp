#include "tools/npy.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "meshcast/errors.h"

namespace meshcast::tools {

namespace {

// The header's dictionary, as numpy writes it: {'descr': '<f4',
// 'fortran_order': False, 'shape': (4, 3), }; the value of a key, or "".
std::string header_value(const std::string& header, const std::string& key) {
  const size_t at = header.find("'" + key + "'");
  if (at == std::string::npos) return "";
  size_t from = header.find(':', at);
  if (from == std::string::npos) return "";
  ++from;
  while (from < header.size() && header[from] == ' ') ++from;
  if (from >= header.size()) return "";
  const char open = header[from];
  const size_t to = open == '(' ? header.find(')', from) : open == '\'' ? header.find('\'', from + 1)
                                                                        : header.find_first_of(",}", from);
  if (to == std::string::npos) return "";
  return header.substr(from, to - from + (open == '(' || open == '\'' ? 1 : 0));
}

template <class T>
void write_values(const std::string& path, const std::vector<uint64_t>& shape, const std::vector<T>& values,
                  const char* descr) {
  std::string dims;
  for (uint64_t d : shape) dims += std::to_string(d) + ", ";
  if (shape.size() > 1) dims.resize(dims.size() - 2);  // (4, 3); a 1-d shape keeps its comma: (4,)
  else if (shape.empty()) dims.clear();
  std::string header = "{'descr': '" + std::string(descr) + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Magic, version, header length, header padded with spaces and a newline
  // to a multiple of 64 bytes.
  const size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  const uint16_t length = uint16_t(header.size());
  out.write("\x93NUMPY\x01\x00", 8);
  out.write(reinterpret_cast<const char*>(&length), 2);
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
  const int major = uint8_t(bytes[6]);
  size_t length = 0, at = 0;
  if (major == 1) {
    length = uint8_t(bytes[8]) | size_t(uint8_t(bytes[9])) << 8, at = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) throw InputError(path + ": a .npy header cut short");
    for (int k = 0; k < 4; ++k) length |= size_t(uint8_t(bytes[8 + k])) << (8 * k);
    at = 12;
  } else {
    throw InputError(path + ": .npy format version " + std::to_string(major) + " (1 to 3 are read)");
  }
  if (bytes.size() < at + length) throw InputError(path + ": a .npy header cut short");
  const std::string header = bytes.substr(at, length);
  const std::string descr = header_value(header, "descr");
  const bool is_double = descr == "'<f8'", is_float = descr == "'<f4'";
  if (!is_double && !is_float)
    throw InputError(path + ": dtype " + (descr.empty() ? "unknown" : descr) +
                     "; float32 or float64 little-endian ('<f4', '<f8') expected");
  if (header_value(header, "fortran_order") != "False")
    throw InputError(path + ": Fortran order; save a C-ordered array (numpy.ascontiguousarray)");
  const std::string shape_text = header_value(header, "shape");
  if (shape_text.size() < 2) throw InputError(path + ": no shape in the .npy header");
  NpyReals out;
  uint64_t count = 1;
  std::stringstream dims(shape_text.substr(1, shape_text.size() - 2));
  for (std::string dim; std::getline(dims, dim, ',');) {
    const size_t first = dim.find_first_not_of(' ');
    if (first == std::string::npos) continue;
    uint64_t d = 0;
    for (size_t k = first; k < dim.size() && dim[k] != ' '; ++k) {
      if (dim[k] < '0' || dim[k] > '9' || d > (uint64_t(1) << 40))
        throw InputError(path + ": shape " + shape_text + " cannot be read");
      d = d * 10 + uint64_t(dim[k] - '0');
    }
    out.shape.push_back(d);
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
