#include "bench/auto.h"

#include <chrono>
#include <cstdio>

namespace meshcast::bench {

std::vector<AutoSetting> auto_settings() {
  std::vector<AutoSetting> out;
  for (const char* text : {"speed", "speed,trial=1024", "memory", "memory,error=2e-6"}) {
    const AutoLimits l = parse_auto_setting(text);
    out.push_back({describe(l), l});
  }
  return out;
}

namespace {

bool meets(const Timing& t, const AutoLimits& l) {
  return (l.max_bytes_per_triangle <= 0 || t.total_bytes <= l.max_bytes_per_triangle) &&
         (l.max_error <= 0 || t.error_bound <= l.max_error);
}

// ns a ray (speed first) or bytes a triangle (memory first): lower is better.
double metric(const Timing& t, const AutoLimits& l, size_t rays) {
  return l.goal == AutoGoal::Speed ? t.min_ms * 1e6 / double(rays) : t.total_bytes;
}

}  // namespace

AutoTable bench_auto(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat) {
  AutoTable table;
  table.combos = bench_combos(mesh, name, rays, repeat);
  const Setup s = setup(mesh, rays);
  for (const AutoSetting& setting : auto_settings()) {
    std::fprintf(stderr, "  auto, %s\n", setting.label.c_str());
    AutoRow row;
    row.setting = setting.label;
    auto t0 = std::chrono::steady_clock::now();
    const AutoChoice choice = choose_layout(mesh, setting.limits, name);
    row.choose_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    row.choice = choice.choice().label;
    row.timing = measure(mesh, name, choice.choice().options, s.rays, s.oracle, repeat);
    row.value = metric(row.timing, setting.limits, rays);
    row.best_value = 1e300;
    for (const TreeRow& c : table.combos) {
      if (!c.refused.empty() || c.timing.disagreements > 0 || !meets(c.timing, setting.limits)) continue;
      ++row.eligible;
      const double v = metric(c.timing, setting.limits, rays);
      if (v < row.best_value) row.best_value = v, row.best = c.layout;
    }
    if (row.eligible == 0) row.best_value = 0;  // nothing to compare with
    table.rows.push_back(row);
  }
  return table;
}

}  // namespace meshcast::bench
