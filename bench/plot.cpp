#include "bench/plot.h"

#include <cstdlib>

#include "check/ray_files.h"

namespace meshcast::bench {

std::string plot_scatter(const std::string& png, const std::string& title, const std::string& xlabel,
                         const std::string& ylabel, const std::vector<Series>& series, bool log_y, bool log_x,
                         bool lines) {
  std::string script = png + ".gp";
  OutputText gp(script);
  size_t points = 0;
  for (const Series& s : series) points += s.points.size();
  // Many labelled points (one per tree and encoding) need room.
  gp << (points > 40 ? "set terminal pngcairo noenhanced size 1800,1200 font 'sans,10'\n" : "set terminal pngcairo noenhanced size 1100,750 font 'sans,10'\n")
     << "set output '" << png << "'\n"
     << "set title '" << title << "'\n"
     << "set xlabel '" << xlabel << "'\nset ylabel '" << ylabel << "'\n"
     << "set grid\nset key top right\nset offsets graph 0.02, graph 0.15, graph 0.05, graph 0.05\n"
     // Log axes ticked every factor of 2 (gnuplot's default, decades, leaves
     // data within one decade without a single label).
     << (log_y ? "set logscale y\nset ytics 2\nset format y '%.1e'\n" : "")
     << (log_x ? "set logscale x\nset xtics 2\nset format x '%g'\n" : "")
     << (log_x || log_y ? "set autoscale fix\n" : "") << "plot ";
  for (size_t s = 0; s < series.size(); ++s) {
    if (s) gp << ", ";
    gp << "'-' using 1:2 with " << (lines ? "linespoints" : "points") << " pt 7 ps 1.2 lc " << s + 1 << " title '" << series[s].title
       << "', '-' using 1:2:3 with labels offset 0.8,0.4 left font 'sans,7' tc lt " << s + 1 << " notitle";
  }
  gp << "\n";
  for (const Series& s : series)
    for (int pass = 0; pass < 2; ++pass) {
      for (const Point& p : s.points) gp << p.x << " " << p.y << " \"" << p.label << "\"\n";
      gp << "e\n";
    }
  gp.commit();
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) return "gnuplot not installed (apt-get install gnuplot-nox)";
  if (std::system(("gnuplot '" + script + "'").c_str()) != 0) return "gnuplot failed on " + script;
  return "";
}

}  // namespace meshcast::bench
