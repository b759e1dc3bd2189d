#include "python/src/parallel.h"

#include <stdexcept>
#include <string>

namespace meshcast::python {

uint32_t thread_count(long long requested, const char* what) {
  if (requested < 0 || requested > 1024)
    throw std::invalid_argument(std::string(what) + " " + std::to_string(requested) + ": from 0 (every core) to 1024");
  return requested ? uint32_t(requested) : host::every_core();
}

}  // namespace meshcast::python
