// Plots through gnuplot (Debian's gnuplot-nox): a scatter of labelled points.
#pragma once
#include <string>
#include <vector>

namespace meshcast::bench {

struct Point {
  double x, y;
  std::string label;
};
struct Series {
  std::string title;
  std::vector<Point> points;
};

// Writes `png` (and the data and script beside it, `png` + ".gp"). Returns ""
// or why no picture was drawn (gnuplot missing or failing). `lines` joins
// each series' points in order.
std::string plot_scatter(const std::string& png, const std::string& title, const std::string& xlabel,
                         const std::string& ylabel, const std::vector<Series>& series, bool log_y, bool log_x = false,
                         bool lines = false);

}  // namespace meshcast::bench
