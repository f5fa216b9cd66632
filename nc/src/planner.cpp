#include "planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

// Geometry is done in the six-dimensional axis space (mm and deg counted alike), so blends,
// directions and per-axis bounds are the same code for 3- and 5-axis moves. Per-axis limits
// become path limits through the direction: along a unit direction u an axis moves |u_i| per
// unit of path, so v <= vmax_i / |u_i| and a <= amax_i / |u_i|. On a blend arc the acceleration
// lies in the arc's plane (unit vectors u, n); an axis sees at most |acc| * sqrt(u_i² + n_i²),
// so the arc's total acceleration is held below A = min_i amax_i / sqrt(u_i² + n_i²) and split
// as LinuxCNC's planner does: tangential 0.5 A, centripetal sqrt(0.75) A (sum of squares = A²).

namespace lbr::nc::detail {
namespace {

using Plan = Emulator::Plan;
using PieceKind = Emulator::PieceKind;

constexpr double kMinLength = 1e-12;       // shorter moves take no time
constexpr double kCollinearCos = 1.0 - 1e-12;  // deflection below ~1.4 µrad: no blend needed
constexpr double kReversalCos = -1.0 + 1e-6;   // deflection near 180°: stop
constexpr int kMaxNaiveMerge = 256;        // moves merged into one chord at most
const double kTangentialShare = 0.5;
const double kNormalShare = std::sqrt(1.0 - kTangentialShare * kTangentialShare);

// One program item after step 1: a straight move or a hold.
struct Move {
  bool hold = false;
  double hold_s = 0.0;
  AxisVector from{}, to{}, u{};
  double length = 0.0;   // [unit]
  double v_nom = 0.0;    // programmed speed along the path [unit/s]
  double v_max = 0.0;    // with the axis velocity limits [unit/s]
  double a_max = 0.0;    // axis acceleration bound along u [unit/s²]
  const Segment* seg = nullptr;
};

[[noreturn]] void invalid(const Toolpath& p, int line, const std::string& m) {
  throw std::invalid_argument(p.source + ":" + std::to_string(line) + ": " + m);
}

double dot(const AxisVector& a, const AxisVector& b) {
  double s = 0.0;
  for (int i = 0; i < kAxes; ++i) s += a[i] * b[i];
  return s;
}

// Programmed speed [mm/s or deg/s] of a segment (rapid rate or capped feed).
double programmed_speed(const Toolpath& path, const Segment& s, const EmulatorLimits& l) {
  if (s.kind == SegmentKind::Rapid) return l.rapid_mm_per_min / 60.0;
  if (!(s.feed_mm_per_min > 0.0) || !std::isfinite(s.feed_mm_per_min))
    invalid(path, s.line, "feed segment without a positive feed rate");
  double f = s.feed_mm_per_min;
  if (l.max_feed_mm_per_min > 0.0) f = std::min(f, l.max_feed_mm_per_min);
  return f / 60.0;
}

// A straight move from -> to for segment s (length 0 when it does not move).
Move make_move(const Toolpath& path, const Segment& s, const AxisVector& from, const AxisVector& to,
               const EmulatorLimits& l) {
  Move m;
  m.seg = &s;
  m.from = from;
  m.to = to;
  AxisVector d{};
  for (int a = 0; a < kAxes; ++a) d[a] = to[a] - from[a];
  const double xyz = std::hypot(d[X], d[Y], d[Z]);
  const double rot = std::hypot(d[A], d[B], d[C]);
  m.length = std::hypot(xyz, rot);
  if (!std::isfinite(m.length)) invalid(path, s.line, "non-finite position");
  if (m.length <= kMinLength) return m;
  // The feed is the XYZ speed (rotary speed for rotary-only moves): scale it to the path.
  const double param = xyz > kMinLength ? xyz : rot;
  m.v_nom = programmed_speed(path, s, l) * m.length / param;
  m.v_max = m.v_nom;
  m.a_max = std::numeric_limits<double>::infinity();
  for (int a = 0; a < kAxes; ++a) {
    m.u[a] = d[a] / m.length;
    const double ua = std::abs(m.u[a]);
    if (ua < 1e-15) continue;
    m.v_max = std::min(m.v_max, l.max_velocity[a] / 60.0 / ua);
    m.a_max = std::min(m.a_max, l.max_accel[a] / ua);
  }
  return m;
}

// Step 1: moves and holds; zero-length moves are dropped.
std::vector<Move> collect_moves(const Toolpath& path, const EmulatorLimits& l) {
  std::vector<Move> out;
  out.reserve(path.segments.size());
  AxisVector pos = path.start;
  for (const Segment& s : path.segments) {
    if (s.kind == SegmentKind::Rapid || s.kind == SegmentKind::Feed) {
      Move m = make_move(path, s, pos, s.end, l);
      if (m.length > kMinLength) out.push_back(m);
    } else {
      Move h;
      h.hold = true;
      h.seg = &s;
      h.from = h.to = s.end;
      if (s.kind == SegmentKind::Dwell) {
        if (!(s.dwell_s >= 0.0) || !std::isfinite(s.dwell_s)) invalid(path, s.line, "dwell time must be >= 0 s");
        h.hold_s = s.dwell_s;
      } else {
        h.hold_s = l.tool_change_s;
      }
      out.push_back(h);
    }
    pos = s.end;
  }
  return out;
}

double point_segment_distance(const AxisVector& p, const AxisVector& a, const AxisVector& b) {
  AxisVector ab{}, ap{};
  for (int i = 0; i < kAxes; ++i) ab[i] = b[i] - a[i], ap[i] = p[i] - a[i];
  const double len2 = dot(ab, ab);
  const double k = len2 > 0.0 ? std::clamp(dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
  double d2 = 0.0;
  for (int i = 0; i < kAxes; ++i) d2 += (ap[i] - k * ab[i]) * (ap[i] - k * ab[i]);
  return std::sqrt(d2);
}

bool mergeable(const Move& a, const Move& b) {
  const Segment& s = *a.seg;
  const Segment& t = *b.seg;
  return !a.hold && !b.hold && s.kind == SegmentKind::Feed && t.kind == SegmentKind::Feed &&
         s.path_control == PathControl::Blend && t.path_control == PathControl::Blend && s.naive_tol_mm > 0.0 &&
         s.feed_mm_per_min == t.feed_mm_per_min && s.tool == t.tool && dot(a.u, b.u) > 0.0;
}

// Step 2: G64 Q — runs of feeds whose vertices stay within Q of the chord become the chord.
std::vector<Move> merge_naive_cam(const Toolpath& path, std::vector<Move> moves, const EmulatorLimits& l) {
  if (std::none_of(moves.begin(), moves.end(), [](const Move& m) { return m.seg->naive_tol_mm > 0.0; })) return moves;
  std::vector<Move> out;
  out.reserve(moves.size());
  std::size_t k = 0;
  while (k < moves.size()) {
    std::size_t j = k;
    while (j + 1 < moves.size() && j + 1 - k < kMaxNaiveMerge && mergeable(moves[j], moves[j + 1])) {
      bool within = true;
      for (std::size_t v = k; v <= j && within; ++v)
        within = point_segment_distance(moves[v].to, moves[k].from, moves[j + 1].to) <= moves[k].seg->naive_tol_mm;
      if (!within) break;
      ++j;
    }
    if (j == k) out.push_back(moves[k]);
    else out.push_back(make_move(path, *moves[k].seg, moves[k].from, moves[j].to, l));
    k = j + 1;
  }
  return out;
}

// Corner at the end of a move (step 3).
struct Corner {
  bool stop = true;
  double trim = 0.0;  // taken from the end of this move and the start of the next [unit]
  bool arc = false;
  Emulator::ArcGeom geom;
  double arc_length = 0.0, v_arc = 0.0, a_arc = 0.0;
};

// The arc's plane bounds: total acceleration A and speed from the axis limits (see the top).
void plane_bounds(const AxisVector& u, const AxisVector& normal, const EmulatorLimits& l, double& acc, double& vel) {
  acc = std::numeric_limits<double>::infinity();
  vel = std::numeric_limits<double>::infinity();
  for (int a = 0; a < kAxes; ++a) {
    const double g = std::hypot(u[a], normal[a]);
    if (g < 1e-15) continue;
    acc = std::min(acc, l.max_accel[a] / g);
    vel = std::min(vel, l.max_velocity[a] / 60.0 / g);
  }
}

// Blend size as LinuxCNC's planner computes it (blendmath.c: tcFindBlendTolerance,
// blendComputeParameters): tolerance T = min(P, L1/4, L2/4) (P = 0: no P bound), at most half
// of each move, the arc as small as the cornering speed needs but not smaller than a
// parabolic blend of the same speed would take.
double blend_radius(const Move& m, const Move& n, double phi, double a_max, double a_n, double v_goal, double& v_plan) {
  const double theta = 0.5 * (std::numbers::pi - phi);  // half the angle between the moves
  double tol = 0.25 * std::min(m.length, n.length);
  for (const Move* k : {&m, &n})
    if (k->seg->blend_tol_mm > 0.0) tol = std::min(tol, k->seg->blend_tol_mm);
  const double d_tol = std::cos(theta) * tol / (1.0 - std::sin(theta));
  const double d_geom = std::min({0.5 * m.length, 0.5 * n.length, d_tol});
  const double r_geom = std::tan(theta) * d_geom;
  v_plan = std::min(std::sqrt(a_n * r_geom), v_goal);
  const double a_parabolic = 0.5 * a_max;
  const double t_blend = std::min(std::sqrt(2.0 * a_parabolic * d_geom), v_plan) / a_parabolic;
  const double r_blend = std::min(t_blend * v_plan / phi, r_geom);
  return std::max(v_plan * v_plan / a_n, r_blend);
}

void blend_arc(const Move& m, const Move& n, double cos_phi, const EmulatorLimits& l, Corner& c) {
  const double phi = std::acos(std::clamp(cos_phi, -1.0, 1.0));
  AxisVector normal{};
  for (int a = 0; a < kAxes; ++a) normal[a] = n.u[a] - cos_phi * m.u[a];
  const double nn = std::sqrt(dot(normal, normal));
  for (int a = 0; a < kAxes; ++a) normal[a] /= nn;
  double acc = 0.0, vel = 0.0;
  plane_bounds(m.u, normal, l, acc, vel);
  const double a_n = kNormalShare * acc;
  double v_plan = 0.0;
  const double radius = blend_radius(m, n, phi, acc, a_n, std::min({vel, m.v_nom, n.v_nom}), v_plan);
  if (!(radius > kMinLength) || !(v_plan > 0.0)) return;  // stop
  c.trim = radius * std::tan(0.5 * phi);
  c.arc = true;
  c.stop = false;
  c.arc_length = radius * phi;
  for (int a = 0; a < kAxes; ++a) {
    c.geom.centre[a] = m.to[a] - c.trim * m.u[a] + radius * normal[a];
    c.geom.e1[a] = -normal[a];
    c.geom.e2[a] = m.u[a];
  }
  c.geom.radius = radius;
  c.geom.normal_accel = a_n;
  c.a_arc = kTangentialShare * acc;
  c.v_arc = v_plan;
}

Corner corner_after(const Move& m, const Move* next, const EmulatorLimits& l) {
  Corner c;
  if (m.hold || next == nullptr || next->hold) return c;
  const PathControl pc = m.seg->path_control;
  if (pc == PathControl::ExactStop) return c;
  // A rapid and a feed are never blended (nor is speed carried over), as in LinuxCNC.
  if ((m.seg->kind == SegmentKind::Rapid) != (next->seg->kind == SegmentKind::Rapid)) return c;
  const double cos_phi = dot(m.u, next->u);
  if (cos_phi >= kCollinearCos) {
    c.stop = false;  // collinear: straight on
    return c;
  }
  if (pc == PathControl::ExactPath || cos_phi <= kReversalCos) return c;
  blend_arc(m, *next, cos_phi, l, c);
  return c;
}

// A piece before the velocity passes, with its speed bound.
struct Piece {
  Plan plan;
  double v_max = 0.0;
  bool stop_before = true;
};

Plan base_plan(const Move& m, PieceKind kind) {
  Plan p;
  p.kind = kind;
  p.tool = m.seg->tool;
  p.line = m.seg->line;
  p.spindle = m.seg->spindle;
  p.spindle_s = m.seg->spindle_s;
  return p;
}

// Step 3: lines shortened by the blends at both ends, arcs between them, holds as they are.
void build_pieces(const std::vector<Move>& moves, const EmulatorLimits& l, std::vector<Piece>& pieces,
                  std::vector<Emulator::ArcGeom>& arcs) {
  pieces.reserve(2 * moves.size());
  double trim_in = 0.0;
  bool stop = true;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const Move& m = moves[i];
    if (m.hold) {
      Piece h{base_plan(m, PieceKind::Hold), 0.0, true};
      h.plan.from = h.plan.to = m.to;
      h.plan.duration_s = m.hold_s;
      pieces.push_back(h);
      stop = true;
      continue;
    }
    const Corner c = corner_after(m, i + 1 < moves.size() ? &moves[i + 1] : nullptr, l);
    Piece line{base_plan(m, PieceKind::Line), m.v_max, stop};
    for (int a = 0; a < kAxes; ++a) {
      line.plan.from[a] = m.from[a] + trim_in * m.u[a];
      line.plan.to[a] = m.to[a] - c.trim * m.u[a];
    }
    line.plan.length = std::max(0.0, m.length - trim_in - c.trim);
    line.plan.a = m.a_max;
    if (line.plan.length > kMinLength) {
      pieces.push_back(line);
      stop = false;
    }
    if (c.arc) {
      Piece arc{base_plan(m, PieceKind::Arc), c.v_arc, stop};
      arc.plan.from = line.plan.to;
      for (int a = 0; a < kAxes; ++a) arc.plan.to[a] = m.to[a] + c.trim * moves[i + 1].u[a];
      arc.plan.length = c.arc_length;
      arc.plan.a = c.a_arc;
      arc.plan.arc = static_cast<int>(arcs.size());
      arcs.push_back(c.geom);
      pieces.push_back(arc);
      stop = false;
    }
    if (c.stop) stop = true;
    trim_in = c.trim;
  }
}

// Step 4: junction speeds. b[k] is the speed where piece k starts (b[n] = 0 at the end).
std::vector<double> junction_speeds(const std::vector<Piece>& pieces) {
  const std::size_t n = pieces.size();
  std::vector<double> b(n + 1, 0.0);
  for (std::size_t k = 1; k < n; ++k) {
    const bool moving = pieces[k].plan.kind != PieceKind::Hold && pieces[k - 1].plan.kind != PieceKind::Hold;
    b[k] = moving && !pieces[k].stop_before ? std::min(pieces[k - 1].v_max, pieces[k].v_max) : 0.0;
  }
  for (std::size_t k = n; k-- > 0;) {  // backward: stop within the remaining path
    const Plan& p = pieces[k].plan;
    b[k] = std::min(b[k], std::sqrt(b[k + 1] * b[k + 1] + 2.0 * p.a * p.length));
  }
  for (std::size_t k = 0; k < n; ++k) {  // forward: reachable from the previous piece
    const Plan& p = pieces[k].plan;
    b[k + 1] = std::min(b[k + 1], std::sqrt(b[k] * b[k] + 2.0 * p.a * p.length));
  }
  return b;
}

// Step 5: trapezoid v_in -> v -> v_out within v_max on the piece's length.
void profile(Piece& piece, double v_in, double v_out) {
  Plan& p = piece.plan;
  if (p.kind == PieceKind::Hold) return;
  const double a = p.a;
  double v = std::min(piece.v_max, std::sqrt(a * p.length + 0.5 * (v_in * v_in + v_out * v_out)));
  v = std::max({v, v_in, v_out});
  p.v_in = v_in;
  p.v = v;
  p.v_out = v_out;
  p.t_acc_s = (v - v_in) / a;
  p.t_dec_s = (v - v_out) / a;
  const double s_acc = (v * v - v_in * v_in) / (2.0 * a);
  const double s_dec = (v * v - v_out * v_out) / (2.0 * a);
  const double cruise = std::max(0.0, p.length - s_acc - s_dec);
  p.duration_s = p.t_acc_s + p.t_dec_s + (v > 0.0 ? cruise / v : 0.0);
}

}  // namespace

PlannedPath plan_path(const Toolpath& path, const EmulatorLimits& limits) {
  std::vector<Move> moves = merge_naive_cam(path, collect_moves(path, limits), limits);
  std::vector<Piece> pieces;
  PlannedPath out;
  build_pieces(moves, limits, pieces, out.arcs);
  const std::vector<double> b = junction_speeds(pieces);
  out.plans.reserve(pieces.size());
  double t = 0.0;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    profile(pieces[k], b[k], b[k + 1]);
    pieces[k].plan.t0_s = t;
    t += pieces[k].plan.duration_s;
    out.plans.push_back(pieces[k].plan);
  }
  out.total_s = t;
  return out;
}

double piece_distance(const Emulator::Plan& p, double tau_s) noexcept {
  if (p.kind == PieceKind::Hold || p.length <= 0.0) return 0.0;
  const double tau = std::clamp(tau_s, 0.0, p.duration_s);
  double s = 0.0;
  if (tau < p.t_acc_s) {
    s = p.v_in * tau + 0.5 * p.a * tau * tau;
  } else if (tau <= p.duration_s - p.t_dec_s) {
    s = (p.v * p.v - p.v_in * p.v_in) / (2.0 * p.a) + p.v * (tau - p.t_acc_s);
  } else {
    const double r = p.duration_s - tau;
    s = p.length - (p.v_out * r + 0.5 * p.a * r * r);
  }
  return std::clamp(s, 0.0, p.length);
}

void piece_position(const Emulator::Plan& p, const std::vector<Emulator::ArcGeom>& arcs, double s,
                    AxisVector& out) noexcept {
  if (p.kind == PieceKind::Hold || p.length <= 0.0 || s >= p.length) {
    out = p.to;
    return;
  }
  if (p.kind == PieceKind::Line) {
    const double k = s / p.length;
    for (int a = 0; a < kAxes; ++a) out[a] = p.from[a] + k * (p.to[a] - p.from[a]);
    return;
  }
  const Emulator::ArcGeom& g = arcs[static_cast<std::size_t>(p.arc)];
  const double th = s / g.radius;
  const double c = g.radius * std::cos(th), sn = g.radius * std::sin(th);
  for (int a = 0; a < kAxes; ++a) out[a] = g.centre[a] + c * g.e1[a] + sn * g.e2[a];
}

}  // namespace lbr::nc::detail
