// cutter_comp.hpp (private) — cutter radius compensation (G41/G42, G41.1/G42.1) as LinuxCNC
// does it (docs/nc-frontend.md#cutter-radius-compensation).
//
// The interpreter hands over programmed moves of the controlled point; the compensated path
// runs at the tool radius beside them, left (G41) or right (G42) of the direction of travel.
// Like LinuxCNC, the end of the last compensated move stays open until the next move is
// known: at a convex corner an arc around the programmed corner is inserted, at a concave
// corner the open end point moves back to where the two offset paths meet — and if it would
// move back past the start of its move, the tool cannot reach the corner without gouging
// and the program is refused. Works in the XY (G17) and ZX (G18) planes. Allocates; errors go
// through the caller's `fail` (which throws ParseError with the file and line).
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "path_builder.hpp"

namespace lbr::nc::detail {

class CutterComp {
 public:
  using Fail = std::function<void(const std::string&)>;  // must throw
  CutterComp(PathBuilder& builder, Fail fail) : b_(builder), fail_(std::move(fail)) {}

  // G41 (side +1) or G42 (side -1) with the tool radius [mm] in plane p.
  void on(int side, double radius_mm, Plane p);
  // G40 (and program end): the last move ends at its offset end point; the program position
  // is the programmed point again (the next move starts from the offset point, as LinuxCNC).
  // Returns true when a move was open (the next move must then be a straight line).
  bool off();
  [[nodiscard]] bool active() const { return side_ != 0; }
  // Program position of the controlled point (the builder lags behind while a move is open).
  [[nodiscard]] const AxisVector& programmed() const { return prog_; }

  void line(int line, bool rapid, const AxisVector& end, double feed, bool inverse_time);
  // Programmed arc from programmed() to end around (cu, cv); rotation as PathBuilder::arc.
  void arc(int line, const AxisVector& end, double cu, double cv, int rotation, double feed, bool inverse_time);
  void dwell(int line, double seconds);

 private:
  enum class Kind : unsigned char { Rapid, Feed, Arc, Dwell };
  struct Item {
    Kind kind = Kind::Feed;
    int line = 0;
    AxisVector end{};
    double feed = 0.0, dwell_s = 0.0;
    bool inverse = false;
    double du = 0.0, dv = 0.0;  // lines: programmed direction (0, 0: not checked)
    double cu = 0.0, cv = 0.0;  // arcs: centre
    int rotation = 0;
    bool xy = false;            // moves in the plane (else: along the third axis only, or a dwell)
  };
  struct Corner {
    bool concave = false, convex = false;  // neither: joined as it is
    double nd = 0.0;                       // direction of the new move at the corner [rad]
  };

  [[noreturn]] void fail(const std::string& m) const;
  void entry_line(int line, bool rapid, const AxisVector& end, double feed, bool inverse);
  void entry_arc(int line, const AxisVector& end, double cu, double cv, int rotation, double feed, bool inverse);
  [[nodiscard]] Corner corner(double nd, bool new_arc_outside) const;
  [[nodiscard]] const Item* open_move() const;
  // The concave corner point where the open move meets the new offset path (line through
  // (pu, pv) with direction nd, or circle around (cu, cv) with radius rc when rc > 0).
  [[nodiscard]] std::array<double, 2> meet(double pu, double pv, double nd, double cu, double cv, double rc) const;
  void corner_arc(int line, bool rapid, const AxisVector& mid, double feed, bool inverse);
  void flush(double u, double v);
  void emit(const Item& it);
  void push(const Item& it);

  PathBuilder& b_;
  Fail fail_;
  int side_ = 0;
  double radius_mm_ = 0.0;
  Plane plane_ = Plane::XY;
  PlaneAxes ax_{X, Y, Z};
  bool first_ = true;
  AxisVector prog_{};  // programmed end of the last move
  AxisVector cur_{};   // compensated end of the last (open) move
  std::vector<Item> open_;
};

}  // namespace lbr::nc::detail
