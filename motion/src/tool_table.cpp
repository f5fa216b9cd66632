#include "motion/tool_table.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lbr::motion {

kin::Mount ToolsConfig::mount_of(int tool) const noexcept {
  if (inserts.count(tool)) return kin::Mount::Turning;
  const auto it = live_mounts.find(tool);
  return it != live_mounts.end() ? it->second : kin::Mount::Spindle;
}

ToolTable::ToolTable(ToolsConfig config, double chord_tol_mm, std::string owner)
    : config_(std::move(config)), chord_tol_mm_(chord_tol_mm), owner_(std::move(owner)) {}

void ToolTable::require(int tool, const std::string& where) {
  if (tool == 0 || built_.count(tool)) return;  // tool 0: empty spindle
  if (const auto it = config_.tools.find(tool); it != config_.tools.end()) {
    const geom::CutterShape& sh =
        cutters_.emplace(tool, geom::CutterShape::build(it->second, chord_tol_mm_)).first->second;
    built_[tool] = ToolRef{tool, &sh, nullptr, mount_of(tool), sh.tool.length_mm, std::hypot(sh.height(), sh.radius())};
    return;
  }
  if (const auto it = config_.inserts.find(tool); it != config_.inserts.end()) {
    const geom::TurningShape& sh =
        inserts_.emplace(tool, geom::TurningShape::build(it->second, chord_tol_mm_)).first->second;
    built_[tool] = ToolRef{tool, nullptr, &sh, kin::Mount::Turning, 0.0, 0.0};
    return;
  }
  throw std::runtime_error(where + ": tool " + std::to_string(tool) + " is not in the tool table of " + owner_);
}

void ToolTable::require_path(const nc::Toolpath& path) {
  for (const nc::Segment& s : path.segments) {
    if (s.kind != nc::SegmentKind::Rapid && s.kind != nc::SegmentKind::Feed && s.kind != nc::SegmentKind::ToolChange)
      continue;
    if (s.tool != 0 && !built_.count(s.tool)) require(s.tool, path.source + ":" + std::to_string(s.line));
    if (s.kind != nc::SegmentKind::ToolChange && cutters_.count(s.tool)) ++motions_[s.tool];
  }
}

void ToolTable::build_all() {
  for (const auto& [n, t] : config_.tools) require(n, owner_);
  for (const auto& [n, t] : config_.inserts) require(n, owner_);
}

ToolRef ToolTable::find(int tool) const noexcept {
  const auto it = built_.find(tool);  // no allocation
  return it == built_.end() ? ToolRef{} : it->second;
}

bool ToolTable::defines(int tool) const noexcept { return config_.tools.count(tool) || config_.inserts.count(tool); }

double ToolTable::dominant_diameter() const {
  double d = 1.0;
  std::size_t most = 0;
  for (const auto& [n, count] : motions_) {
    if (count > most) {
      most = count;
      d = std::max(1.0, cutters_.at(n).tool.diameter_mm);
    }
  }
  return d;
}

double ToolTable::max_diameter() const {
  double d = 1.0;
  for (const auto& [n, t] : config_.tools) d = std::max(d, t.diameter_mm);
  return d;
}

}  // namespace lbr::motion
