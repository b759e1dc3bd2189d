#include "host/crossover.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
#include <vector>

#include "meshcast/errors.h"
#include "host/profile.h"
#include "layout/blob_format.h"

namespace meshcast::host {

std::string profile_key(const std::string& device, const BlobView& view) {
  const layout::BlobHeader& h = layout::header_of(view.bytes().data());
  return device + " | " + std::string(layout::tree_format_name(h.tree_format)) + "/" +
         std::string(layout::triangle_format_name(h.triangle_format)) + " | " + std::to_string(h.triangle_count) +
         " triangles | " + std::to_string(h.checksum);
}

std::string Crossover::note() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return note_;
}

std::string Crossover::unused_profile() const {
  return profile_unused_.empty() ? "" : " (the profile was not used: " + profile_unused_ + ")";
}

bool Crossover::load(const std::string& path, const std::string& key) {
  if (path.empty()) return false;
  const SavedProfile saved = read_profile(path, key);
  if (!saved.crossover) {
    profile_unused_ = saved.note;
    profile_replaceable_ = saved.replaceable;
    return false;
  }
  rays_ = *saved.crossover;
  note_ = saved.note + ", loaded from " + path;
  known_ = true;
  return true;
}

void Crossover::measure_in_background(Measurement m) {
  note_ = "being measured in the background" + unused_profile() + "; the CPU answers meanwhile";
  measuring_ = std::thread([this, m = std::move(m)] {
    try {
      measure(m);  // publishes the crossover, its note and known_ together
    } catch (const GpuError& e) {  // the GPU failed while measured: the CPU it is
      m.gpu_failed(std::string("measuring the crossover: ") + e.what());
    } catch (const std::exception& e) {  // anything else (memory): the GPU stays, the crossover stays unmeasured
      std::lock_guard<std::mutex> lock(mutex_);
      note_ = std::string("not measured: ") + e.what();
    } catch (...) {  // an engine's job system may throw a type of its own: nothing may leave this thread
      std::lock_guard<std::mutex> lock(mutex_);
      note_ = "not measured: the job system threw an exception not derived from std::exception";
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      known_ = true;
    }
    changed_.notify_all();
  });
}

void Crossover::stop() {
  stop_measuring_ = true;
  if (measuring_.joinable()) measuring_.join();
}

// The crossover: the smallest measured batch size from which on the GPU
// returned every size first (median of 3 batches a size and backend),
// measured on rays aimed at the blob's box from around it, on the slot
// after the game's (its batches are not the game's records), then saved to
// the profile when one is named.
void Crossover::measure(const Measurement& m) {
  const layout::BlobHeader& h = layout::header_of(m.blob->bytes().data());
  std::vector<Ray> rays(16384);
  uint64_t state = 0x9E3779B97F4A7C15ull;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return float(double(state >> 40) / double(1ull << 24));
  };
  float centre[3], extent = 0;
  for (int a = 0; a < 3; ++a)
    centre[a] = 0.5f * (h.bounds_min[a] + h.bounds_max[a]), extent = std::max(extent, h.bounds_max[a] - h.bounds_min[a]);
  for (Ray& r : rays) {
    for (int a = 0; a < 3; ++a) {
      r.org[a] = centre[a] + extent * (2 * uniform() - 1);
      r.dir[a] = h.bounds_min[a] + (h.bounds_max[a] - h.bounds_min[a]) * uniform() - r.org[a];
    }
    r.tmax = INFINITY;
  }
  std::vector<Hit> hits(rays.size());
  std::vector<uint32_t> sizes;
  std::vector<double> cpu, gpu;
  for (uint32_t n = 1; n <= rays.size(); n *= 4) {
    sizes.push_back(n);
    for (Backend b : {Backend::Cpu, Backend::Vulkan}) {
      std::vector<double> ms;
      for (int k = 0; k < 3; ++k) {
        if (stop_measuring_) return;
        ms.push_back(m.time_batch(std::span<const Ray>(rays).first(n), hits, b));
      }
      std::sort(ms.begin(), ms.end());
      (b == Backend::Cpu ? cpu : gpu).push_back(ms[1]);
    }
  }
  if (!m.gpu_available()) return;
  size_t first = sizes.size();
  while (first > 0 && gpu[first - 1] < cpu[first - 1]) --first;
  const size_t at = first < sizes.size() ? first : sizes.size() - 1;
  std::ostringstream note;
  note << "at " << sizes[at] << " rays " << m.device << " took " << gpu[at] << " ms, " << m.cpu_threads()
       << " CPU threads " << cpu[at] << " ms; measured at start-up";
  const uint32_t crossover = first < sizes.size() ? sizes[first] : ~0u;
  std::string saved = unused_profile();
  if (!m.profile.empty() && !profile_replaceable_) {
    saved += "; not saved: " + m.profile + " is left as it is";
  } else if (!m.profile.empty()) {
    try {
      write_profile(m.profile, profile_key(m.device, *m.blob), crossover, note.str());
    } catch (const OutputError& e) {  // the crossover stands; only the next start measures again
      saved += std::string("; not saved: ") + e.what();
    }
  }
  // Published together, after the profile is written: no reader sees a
  // crossover without its note, or a known crossover the file lacks.
  std::lock_guard<std::mutex> lock(mutex_);
  note_ = note.str() + saved;
  rays_ = crossover;
  known_ = true;
}

}  // namespace meshcast::host
