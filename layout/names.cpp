// Layouts by name: listed, named, parsed, and the nearest names offered
// for a typo.
#include "layout/names.h"

#include <algorithm>
#include <cctype>

#include "layout/blob_format.h"
#include "layout/catalog.h"
#include "layout/triangles/codecs.h"
#include "layout/tree/zerobyte.h"
#include "meshcast/errors.h"

namespace meshcast {

// The public names (meshcast/build.h) are the ids a blob stores (the tree
// formats' are checked in layout/catalog.h).
#define MC_PUBLIC_ID(Codec, name) static_assert(uint32_t(TriangleFormat::Codec) == layout::Codec::kFormat);
MC_FOR_EACH_TRIANGLE_CODEC(MC_PUBLIC_ID)
#undef MC_PUBLIC_ID
static_assert(uint32_t(TriangleFormat::Indexed24) == layout::Indexed24::kFormat);

// The catalog's trees in its order, each with the triangle formats it takes.
std::vector<Layout> all_layouts() {
  std::vector<Layout> all;
#define MC_TREE_LAYOUTS(Name, ...)                                                                  \
  if constexpr (layout::tree::Name::kTriangles == layout::TreeTriangles::AllCodecs) {                \
    for (uint32_t c : {MC_FOR_EACH_TRIANGLE_CODEC(MC_CODEC_ID)}) all.push_back({TreeFormat::Name, TriangleFormat(c)}); \
  } else {                                                                                            \
    all.push_back({TreeFormat::Name, TriangleFormat::Indexed24});                                     \
  }
#define MC_CODEC_ID(Codec, name) layout::Codec::kFormat,
  MC_FOR_EACH_TREE_FORMAT(MC_TREE_LAYOUTS)
#undef MC_CODEC_ID
#undef MC_TREE_LAYOUTS
  return all;
}

std::vector<std::string> layout_names() {
  std::vector<std::string> names;
  for (Layout l : all_layouts()) names.push_back(layout_name(l));
  return names;
}

std::string layout_name(uint32_t tree, uint32_t triangles) {
  return std::string(layout::tree_format_name(tree)) + "/" + std::string(layout::triangle_format_name(triangles));
}

std::string layout_name(Layout l) { return layout_name(uint32_t(l.tree), uint32_t(l.triangles)); }

Layout parse_layout_name(const std::string& text) {
  auto lower = [](std::string s) {
    for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  for (Layout l : all_layouts())
    if (lower(layout_name(l)) == lower(text)) return l;
  throw InputError("unknown layout '" + text + "'; did you mean " + closest_layouts(text) + "? (TREE/TRIANGLES; `meshcast layouts` lists all " +
                   std::to_string(all_layouts().size()) + ")");
}

namespace {

// Edits (insertions, deletions, substitutions) from a to b, case folded.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({up + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// How far a typed part of a name is from a real one: 0 the same, 1 a
// piece of it ("OctTree" of "OctTreeCompressed"), else the edits.
size_t part_distance(const std::string& typed, const std::string& real) {
  auto lower = [](std::string s) {
    for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  const std::string t = lower(typed), r = lower(real);
  if (t == r) return 0;
  if (!t.empty() && r.find(t) != std::string::npos) return 1;
  return edit_distance(t, r);
}

// "A, B or C": the first `count` names.
std::string listed(const std::vector<std::string>& names, size_t count) {
  std::string out;
  const size_t n = std::min(count, names.size());
  for (size_t i = 0; i < n; ++i) out += (i == 0 ? "" : i + 1 == n ? " or " : ", ") + names[i];
  return out;
}

}  // namespace

std::string closest_layouts(const std::string& text) {
  const size_t slash = text.find('/');
  // Nearest tree first, then nearest triangle format: a tree typed right
  // with a triangle format it does not take is answered with the ones it
  // does. Without a slash the text may name either half.
  struct Scored {
    size_t first, second;
    std::string name;
  };
  std::vector<Scored> scored;
  for (Layout l : all_layouts()) {
    const std::string tree(layout::tree_format_name(uint32_t(l.tree)));
    const std::string triangles(layout::triangle_format_name(uint32_t(l.triangles)));
    if (slash == std::string::npos)
      scored.push_back({std::min(part_distance(text, tree), part_distance(text, triangles)), 0, tree + "/" + triangles});
    else
      scored.push_back({part_distance(text.substr(0, slash), tree), part_distance(text.substr(slash + 1), triangles),
                        tree + "/" + triangles});
  }
  std::stable_sort(scored.begin(), scored.end(), [](const Scored& a, const Scored& b) {
    return a.first != b.first ? a.first < b.first : a.second < b.second;
  });
  std::vector<std::string> names;
  for (const Scored& s : scored) names.push_back(s.name);
  return listed(names, 3);
}

std::string closest_names(const std::string& text, const std::vector<std::string>& names, size_t count) {
  std::vector<std::string> sorted = names;
  std::stable_sort(sorted.begin(), sorted.end(), [&](const std::string& a, const std::string& b) {
    return part_distance(text, a) < part_distance(text, b);
  });
  return listed(sorted, count);
}

}  // namespace meshcast
