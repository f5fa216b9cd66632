// motion/tool_table.hpp — the tools a run cuts with: milling cutters and lathe inserts, their
// mount on the machine and their sweep shapes (geom::CutterShape / geom::TurningShape), built
// once at setup. Addresses of built shapes stay valid for the table's lifetime, so sweeps
// (geom::SweepRef) point into it.
//
// Setup calls (constructor, require*, build_all) allocate and may throw; find(), mount_of()
// and defines() are real-time safe: no allocation, no exceptions, no locks.
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include "geom/sweep.hpp"  // CutterShape
#include "geom/tool.hpp"
#include "geom/turning.hpp"
#include "kin/kinematics.hpp"
#include "nc/toolpath.hpp"

namespace lbr::motion {

// The tool definitions of a machine (a profile's [[tool]] tables): milling tools and turning
// inserts share one numbering; `live_mounts` says how a lathe-c holds each milling tool.
struct ToolsConfig {
  std::map<int, geom::Tool> tools;           // milling tools (spindle or live tools)
  std::map<int, geom::TurningTool> inserts;  // turning tools (lathe kinds)
  std::map<int, kin::Mount> live_mounts;     // lathe-c: mount of each milling tool
  // Mount of tool n on this machine (Turning for inserts, Spindle on mills).
  [[nodiscard]] kin::Mount mount_of(int tool) const noexcept;
};

// A built tool as the sweep code sees it. A default ToolRef (no shape) cuts nothing.
struct ToolRef {
  int number = 0;
  const geom::CutterShape* shape = nullptr;    // milling cutter, or null
  const geom::TurningShape* turning = nullptr; // turning insert, or null
  kin::Mount mount = kin::Mount::Spindle;
  double length_mm = 0.0;  // gauge length (mill5 heads without TCP need it) [mm]
  double reach_mm = 0.0;   // farthest cutting point from the tip [mm]
  [[nodiscard]] bool cuts() const noexcept { return shape != nullptr || turning != nullptr; }
  [[nodiscard]] bool same(const ToolRef& o) const noexcept { return shape == o.shape && turning == o.turning; }
};

class ToolTable {
 public:
  // `owner` names the tool table in messages (the profile's file name); shapes are built
  // with `chord_tol_mm`.
  ToolTable(ToolsConfig config, double chord_tol_mm, std::string owner);
  ToolTable(const ToolTable&) = delete;  // sweeps point into the table
  ToolTable& operator=(const ToolTable&) = delete;

  // Setup: builds tool n's shape if not built yet. Tool 0 (empty spindle) is ignored. Throws
  // std::runtime_error "`where`: tool N is not in the tool table of OWNER" for an unknown tool.
  void require(int tool, const std::string& where);
  // Setup: require() for every tool a path's motions and tool changes use (`where` = the
  // path's source:line), counting the motion segments of each milling tool.
  void require_path(const nc::Toolpath& path);
  // Setup: builds every defined tool.
  void build_all();

  // The built tool n, or a ToolRef that cuts nothing. Real-time safe.
  [[nodiscard]] ToolRef find(int tool) const noexcept;
  [[nodiscard]] bool defines(int tool) const noexcept;
  [[nodiscard]] kin::Mount mount_of(int tool) const noexcept { return config_.mount_of(tool); }
  [[nodiscard]] const ToolsConfig& config() const noexcept { return config_; }
  [[nodiscard]] double chord_tol_mm() const noexcept { return chord_tol_mm_; }

  // Diameter [mm] of the milling tool with the most motion segments counted by
  // require_path() (for a sampled program: the longest time in the spindle); at least 1.
  // The automatic region grid is sized for it.
  [[nodiscard]] double dominant_diameter() const;
  // Largest milling tool diameter [mm] of the definitions; at least 1.
  [[nodiscard]] double max_diameter() const;

 private:
  ToolsConfig config_;
  double chord_tol_mm_;
  std::string owner_;
  std::map<int, geom::CutterShape> cutters_;
  std::map<int, geom::TurningShape> inserts_;
  std::map<int, ToolRef> built_;
  std::map<int, std::size_t> motions_;  // motion segments per milling tool
};

}  // namespace lbr::motion
