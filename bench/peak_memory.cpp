#include "bench/peak_memory.h"

#include <malloc.h>

#include <cstdio>
#include <cstring>

namespace meshcast::bench {

namespace {

// A "Field:   N kB" line of /proc/self/status, in bytes; -1 if absent.
double status_bytes(const char* field) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return -1;
  char line[256];
  double bytes = -1;
  const size_t n = std::strlen(field);
  while (std::fgets(line, sizeof line, f))
    if (std::strncmp(line, field, n) == 0 && line[n] == ':') {
      unsigned long long kb = 0;
      if (std::sscanf(line + n + 1, "%llu", &kb) == 1) bytes = double(kb) * 1024;
      break;
    }
  std::fclose(f);
  return bytes;
}

// Writing 5 to clear_refs sets the high-water mark to the resident size now.
bool reset_peak() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool written = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && written;
}

}  // namespace

double peak_added_bytes(const std::function<void()>& work) {
  // The heap's free pages handed back first: memory freed by earlier work,
  // reused by this, would otherwise not count towards its peak.
  malloc_trim(0);
  const bool reset = reset_peak();
  const double before = status_bytes("VmRSS");
  work();
  const double peak = status_bytes("VmHWM");
  if (!reset || before < 0 || peak < before) return 0;
  return peak - before;
}

}  // namespace meshcast::bench
