#include "app/tune.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <regex>
#include <sstream>

#include "app/batch.hpp"

namespace lbr::app {

std::vector<std::pair<int, int>> tune_candidates(const Profile& p, double max_tool_diameter_mm) {
  double wx, wy;
  if (p.solid.shape == geom::SolidSpec::Shape::Box) {
    wx = p.solid.box.max.x - p.solid.box.min.x;
    wy = p.solid.box.max.y - p.solid.box.min.y;
  } else {
    wx = wy = p.solid.cylinder.diameter_mm;
  }
  std::vector<std::pair<int, int>> out;
  for (int nx : {1, 2, 4, 8, 16})
    for (int ny : {1, 2, 4, 8, 16}) {
      if (std::abs(std::log2(static_cast<double>(nx) / ny)) > 1.0) continue;
      if (wx / nx < max_tool_diameter_mm && nx > 1) continue;
      if (wy / ny < max_tool_diameter_mm && ny > 1) continue;
      out.emplace_back(nx, ny);
    }
  return out;
}

std::vector<GridTiming> tune_regions(const Profile& p, const nc::Toolpath& path,
                                     const std::vector<std::pair<int, int>>& grids, int repeats,
                                     const std::function<void(const GridTiming&)>& report) {
  std::vector<GridTiming> out;
  for (const auto& [nx, ny] : grids) {
    Profile q = p;
    q.regions_auto = false;
    q.solid.regions_x = nx;
    q.solid.regions_y = ny;
    q.threads = 1;
    GridTiming t{nx, ny, INFINITY, 0};
    for (int r = 0; r < std::max(1, repeats); ++r) {
      const BatchResult b = run_batch(q, path);
      t.wall_s = std::min(t.wall_s, b.wall_time_s);
      t.removed_mm3 = b.removed_volume_mm3;
    }
    out.push_back(t);
    if (report) report(t);
  }
  std::sort(out.begin(), out.end(), [](const GridTiming& a, const GridTiming& b) { return a.wall_s < b.wall_s; });
  return out;
}

std::string set_regions_in_profile_text(const std::string& text, int nx, int ny) {
  const std::string value = "regions = \"" + std::to_string(nx) + "x" + std::to_string(ny) + "\"";
  std::istringstream in(text);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const std::regex table(R"(^\s*\[\s*([A-Za-z0-9_.]+)\s*\]\s*(#.*)?$)");
  const std::regex regions_key(R"(^\s*regions\s*=)");
  std::string current;
  int lbr_header = -1;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    std::smatch m;
    if (std::regex_match(lines[i], m, table) || lines[i].find("[[") != std::string::npos) {
      current = m.size() > 1 ? m[1].str() : "";
      if (current == "lbr") lbr_header = static_cast<int>(i);
      continue;
    }
    if (current == "lbr" && std::regex_search(lines[i], regions_key)) {
      lines[i] = value;
      lbr_header = -2;  // done
      break;
    }
  }
  if (lbr_header >= 0) {
    lines.insert(lines.begin() + lbr_header + 1, value);
  } else if (lbr_header == -1) {
    lines.push_back("");
    lines.push_back("[lbr]");
    lines.push_back(value);
  }
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

}  // namespace lbr::app
