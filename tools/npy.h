// numpy's .npy files (format 1.0 and 2.0, little-endian, C order), as the
// command line reads query points and writes distances: what numpy users
// open with numpy.load. Only the dtypes the commands use.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace meshcast::tools {

// An array of float32 or float64 values, read as double, and its shape.
struct NpyReals {
  std::vector<uint64_t> shape;
  std::vector<double> values;
};
// InputError naming the path: not a .npy file, a format version numpy
// does not write, a header numpy would refuse (not the dictionary literal
// of descr, fortran_order and shape, more than 10000 bytes, more than 32
// dimensions), a dtype other than '<f4' or '<f8', Fortran order, or fewer
// bytes than the shape says.
NpyReals read_npy_reals(const std::string& path);

// Writes float32 ('<f4') or uint32 ('<u4') values of `shape` (format 1.0,
// or 2.0 where the header is beyond 1.0's 16-bit length); InputError naming
// the path for a shape of more than 32 dimensions (numpy reads no more),
// OutputError when it cannot be written.
void write_npy(const std::string& path, const std::vector<uint64_t>& shape, const std::vector<float>& values);
void write_npy(const std::string& path, const std::vector<uint64_t>& shape, const std::vector<uint32_t>& values);

}  // namespace meshcast::tools
