#include "cutter_comp.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace lbr::nc::detail {

namespace {

constexpr double kPi = std::numbers::pi;
// LinuxCNC's TOLERANCE_CONCAVE_CORNER: corners that turn less than this [rad] are joined
// without a corner arc or a cut-back.
constexpr double kCornerTol = 0.05;

double norm_angle(double a) { return std::remainder(a, 2.0 * kPi); }  // in [-pi, pi]

std::string mm(double v) {
  std::ostringstream o;
  o << v;
  return o.str() + " mm";
}

// Angle swept from a0 to a1 in the direction of rotation (> 0: counter-clockwise), in [0, 2 pi).
double sweep(double a0, double a1, int rotation) {
  double s = std::fmod(rotation > 0 ? a1 - a0 : a0 - a1, 2.0 * kPi);
  if (s < 0.0) s += 2.0 * kPi;
  return s;
}

}  // namespace

void CutterComp::fail(const std::string& m) const {
  fail_(m);
  throw std::logic_error("CutterComp: the fail callback returned");
}

void CutterComp::on(int side, double radius_mm, Plane p) {
  if (side_ != 0) fail("cannot turn cutter radius compensation on when it is already on");
  if (p == Plane::YZ) fail("cutter radius compensation needs plane G17 (XY) or G18 (XZ)");
  side_ = side;
  radius_mm_ = radius_mm;
  plane_ = p;
  ax_ = plane_axes(p);
  first_ = true;
  prog_ = cur_ = b_.position();
  open_.clear();
}

bool CutterComp::off() {
  const bool was_open = side_ != 0 && radius_mm_ > 0.0 && !first_;
  if (was_open) {
    flush(cur_[ax_.u], cur_[ax_.v]);
    b_.set_position(prog_);
  }
  side_ = 0;
  first_ = true;
  return was_open;
}

void CutterComp::line(int line, bool rapid, const AxisVector& end, double feed, bool inverse_time) {
  if (radius_mm_ <= 0.0) {
    if (rapid) b_.rapid(line, end);
    else b_.feed(line, end, feed, inverse_time);
    prog_ = cur_ = end;
    return;
  }
  if (first_) return entry_line(line, rapid, end, feed, inverse_time);
  const int u = ax_.u, v = ax_.v;
  Item it;
  it.kind = rapid ? Kind::Rapid : Kind::Feed;
  it.line = line;
  it.end = end;
  it.feed = feed;
  it.inverse = inverse_time;
  const double du = end[u] - prog_[u], dv = end[v] - prog_[v];
  if (std::hypot(du, dv) < 1e-12) {  // along the third axis only: stays beside the corner
    it.end[u] = cur_[u], it.end[v] = cur_[v];
    push(it);
    prog_ = end;
    return;
  }
  const double nd = std::atan2(dv, du), n = nd + side_ * 0.5 * kPi;
  it.end[u] += radius_mm_ * std::cos(n), it.end[v] += radius_mm_ * std::sin(n);
  it.du = std::cos(nd), it.dv = std::sin(nd), it.xy = true;
  const Corner k = corner(nd, false);
  if (k.concave) {
    const auto q = meet(it.end[u], it.end[v], nd, 0.0, 0.0, 0.0);
    flush(q[0], q[1]);
  } else {
    flush(cur_[u], cur_[v]);
    if (k.convex) {
      AxisVector mid = b_.position();
      mid[u] = prog_[u] + radius_mm_ * std::cos(n), mid[v] = prog_[v] + radius_mm_ * std::sin(n);
      corner_arc(line, rapid, mid, feed, inverse_time);
    }
  }
  push(it);
  prog_ = end;
}

void CutterComp::arc(int line, const AxisVector& end, double cu, double cv, int rotation, double feed,
                     bool inverse_time) {
  if (radius_mm_ <= 0.0) {
    b_.arc(line, plane_, end, cu, cv, rotation, feed, inverse_time);
    prog_ = cur_ = end;
    return;
  }
  const int u = ax_.u, v = ax_.v;
  const bool inside = side_ * rotation > 0;  // G41 with G3, G42 with G2: the tool is inside the arc
  const double re = std::hypot(end[u] - cu, end[v] - cv);
  if (inside && re <= radius_mm_)
    fail("the tool radius (" + mm(radius_mm_) + ") is not less than the arc radius (" + mm(re) + ") with cutter compensation");
  if (first_) return entry_arc(line, end, cu, cv, rotation, feed, inverse_time);
  Item it;
  it.kind = Kind::Arc;
  it.line = line;
  it.end = end;
  const double off_r = inside ? -radius_mm_ : radius_mm_;
  it.end[u] += off_r * (end[u] - cu) / re, it.end[v] += off_r * (end[v] - cv) / re;
  it.feed = feed, it.inverse = inverse_time, it.cu = cu, it.cv = cv, it.rotation = rotation, it.xy = true;
  const double a0 = std::atan2(prog_[v] - cv, prog_[u] - cu);
  const double nd = a0 + (rotation > 0 ? 0.5 : -0.5) * kPi, n = nd + side_ * 0.5 * kPi;
  AxisVector mid = cur_;
  mid[u] = prog_[u] + radius_mm_ * std::cos(n), mid[v] = prog_[v] + radius_mm_ * std::sin(n);
  const Corner k = corner(nd, !inside);
  if (k.concave) {
    const auto q = meet(0.0, 0.0, 0.0, cu, cv, std::hypot(mid[u] - cu, mid[v] - cv));
    flush(q[0], q[1]);
  } else {
    flush(cur_[u], cur_[v]);
    if (k.convex) corner_arc(line, false, mid, feed, inverse_time);
  }
  push(it);
  prog_ = end;
}

void CutterComp::dwell(int line, double seconds) {
  if (open_.empty()) return b_.dwell(line, seconds);
  Item it;
  it.kind = Kind::Dwell;
  it.line = line;
  it.end = cur_;
  it.dwell_s = seconds;
  open_.push_back(it);
}

// First move after G41/G42, a line: it ends beside its programmed end point, square to its
// direction (LinuxCNC's convert_straight_comp1).
void CutterComp::entry_line(int line, bool rapid, const AxisVector& end, double feed, bool inverse) {
  const int u = ax_.u, v = ax_.v;
  const double d = std::hypot(end[u] - cur_[u], end[v] - cur_[v]);
  if (d <= radius_mm_)
    fail("the cutter compensation entry move (" + mm(d) + " in the plane) is not longer than the tool radius (" + mm(radius_mm_) +
         ")");
  const double n = std::atan2(end[v] - cur_[v], end[u] - cur_[u]) + side_ * 0.5 * kPi;
  Item it;
  it.kind = rapid ? Kind::Rapid : Kind::Feed;
  it.line = line;
  it.end = end;
  it.end[u] += radius_mm_ * std::cos(n), it.end[v] += radius_mm_ * std::sin(n);
  it.feed = feed, it.inverse = inverse, it.xy = true;
  push(it);
  prog_ = end;
  first_ = false;
}

// First move after G41/G42, an arc: it ends beside its programmed end point on the radius
// through it; its centre moves along that radius until start and end are equally far from it
// (LinuxCNC's convert_arc_comp1).
void CutterComp::entry_arc(int line, const AxisVector& end, double cu, double cv, int rotation, double feed,
                           bool inverse) {
  const int u = ax_.u, v = ax_.v;
  const double re = std::hypot(end[u] - cu, end[v] - cv);
  const double wu = (end[u] - cu) / re, wv = (end[v] - cv) / re;  // radius through the end point
  const double off_r = side_ * rotation > 0 ? -radius_mm_ : radius_mm_;
  Item it;
  it.kind = Kind::Arc;
  it.line = line;
  it.end = end;
  it.end[u] += off_r * wu, it.end[v] += off_r * wv;
  const double su = cur_[u] - cu, sv = cur_[v] - cv, eu = it.end[u] - cu, ev = it.end[v] - cv;
  const double den = 2.0 * (wu * (su - eu) + wv * (sv - ev));
  if (std::abs(den) < 1e-12)
    fail("cutter compensation entry arc: no circle through its start and its offset end point");
  const double t = (su * su + sv * sv - eu * eu - ev * ev) / den;
  it.feed = feed, it.inverse = inverse, it.cu = cu + t * wu, it.cv = cv + t * wv, it.rotation = rotation, it.xy = true;
  push(it);
  prog_ = end;
  first_ = false;
}

// How the path turns at the programmed corner prog_, as LinuxCNC classifies it: the open
// move's direction there follows from its offset end point cur_ (on the tool side, square to
// the direction); beta is the turn away from the tool side in [-pi/2, 3pi/2). Concave: beta
// < 0 or > pi (beyond the tolerance), or a reversal after an arc that curves away from the
// tool (LinuxCNC's "h" shape) or before an arc with the tool outside it (new_arc_outside);
// convex (corner arc): 0 < beta <= pi. (Both reversal rules found with rs274.)
CutterComp::Corner CutterComp::corner(double nd, bool new_arc_outside) const {
  const double pd = std::atan2(cur_[ax_.v] - prog_[ax_.v], cur_[ax_.u] - prog_[ax_.u]) - side_ * 0.5 * kPi;
  double beta = norm_angle(side_ * (pd - nd));
  if (beta < -0.5 * kPi) beta += 2.0 * kPi;
  const Item* open = open_move();
  const bool reversal = beta > kPi - kCornerTol;
  const bool h_shape = open != nullptr && open->kind == Kind::Arc && side_ * open->rotation < 0;
  Corner k;
  k.concave = beta < -kCornerTol || beta > kPi + kCornerTol || (reversal && (h_shape || new_arc_outside));
  k.convex = !k.concave && beta > kCornerTol;
  k.nd = nd;
  return k;
}

const CutterComp::Item* CutterComp::open_move() const {
  for (const Item& it : open_)
    if (it.xy) return &it;
  return nullptr;
}

std::array<double, 2> CutterComp::meet(double pu, double pv, double nd, double cu, double cv, double rc) const {
  const int u = ax_.u, v = ax_.v;
  const Item* prev = open_move();
  const double eu = cur_[u], ev = cur_[v];  // end of the open move, to be moved back
  const bool prev_arc = prev != nullptr && prev->kind == Kind::Arc;
  const char* what = prev_arc ? (rc > 0.0 ? "arc to arc" : "arc to straight") : (rc > 0.0 ? "straight to arc" : "straight to straight");
  auto no_room = [&] {
    fail(std::string(what) + " motion makes a corner the compensated tool (radius " + mm(radius_mm_) +
         ") cannot fit in without gouging");
  };
  // Of the points where the paths meet, the one the open move reaches last going back from its
  // end: the smallest angle back along an open arc, the nearest point behind the end of an
  // open line (a point ahead of it only when there is none behind).
  std::array<double, 2> best{eu, ev};
  double best_cost = INFINITY;
  const double pdir = std::atan2(ev - prog_[v], eu - prog_[u]) - side_ * 0.5 * kPi;
  auto take = [&](double qu, double qv) {
    double cost = 0.0;
    if (prev_arc) {
      cost = sweep(std::atan2(qv - prev->cv, qu - prev->cu), std::atan2(ev - prev->cv, eu - prev->cu), prev->rotation);
    } else {
      const double t = (qu - eu) * std::cos(pdir) + (qv - ev) * std::sin(pdir);  // < 0: behind the end
      cost = t <= 1e-9 ? -t : 1e6 + t;
    }
    if (cost < best_cost) best = {qu, qv}, best_cost = cost;
  };
  if (!prev_arc) {
    // The open line's programmed direction (square to its offset at the corner): for the
    // entry move that is not the direction from its start, and LinuxCNC uses this one.
    const double du = std::cos(pdir), dv = std::sin(pdir);
    if (rc <= 0.0) {  // line with line p + w (cos nd, sin nd)
      const double wu = std::cos(nd), wv = std::sin(nd), den = du * wv - dv * wu;
      if (std::abs(den) < 1e-12) no_room();
      const double t = ((pu - eu) * wv - (pv - ev) * wu) / den;
      take(eu + t * du, ev + t * dv);
    } else {  // line with circle (c, rc)
      const double a = du * du + dv * dv, bq = 2.0 * (du * (eu - cu) + dv * (ev - cv));
      const double cq = (eu - cu) * (eu - cu) + (ev - cv) * (ev - cv) - rc * rc, disc = bq * bq - 4.0 * a * cq;
      if (disc < 0.0) no_room();
      for (double sgn : {-1.0, 1.0}) {
        const double t = (-bq + sgn * std::sqrt(disc)) / (2.0 * a);
        take(eu + t * du, ev + t * dv);
      }
    }
  } else {
    const double ou = prev->cu, ov = prev->cv, ro = std::hypot(eu - ou, ev - ov);
    if (rc <= 0.0) {  // circle with line p + w (cos nd, sin nd)
      const double wu = std::cos(nd), wv = std::sin(nd);
      const double bq = 2.0 * (wu * (pu - ou) + wv * (pv - ov));
      const double cq = (pu - ou) * (pu - ou) + (pv - ov) * (pv - ov) - ro * ro, disc = bq * bq - 4.0 * cq;
      if (disc < 0.0) no_room();
      for (double sgn : {-1.0, 1.0}) {
        const double w = (-bq + sgn * std::sqrt(disc)) / 2.0;
        take(pu + w * wu, pv + w * wv);
      }
    } else {  // circle with circle
      const double d = std::hypot(cu - ou, cv - ov);
      if (d < 1e-12 || d > ro + rc || d < std::abs(ro - rc)) no_room();
      const double a = (ro * ro - rc * rc + d * d) / (2.0 * d), h = std::sqrt(std::max(0.0, ro * ro - a * a));
      const double mu = ou + a * (cu - ou) / d, mv = ov + a * (cv - ov) / d;
      take(mu + h * (cv - ov) / d, mv - h * (cu - ou) / d);
      take(mu - h * (cv - ov) / d, mv + h * (cu - ou) / d);
    }
  }
  return best;
}

void CutterComp::corner_arc(int line, bool rapid, const AxisVector& mid, double feed, bool inverse) {
  if (rapid) b_.rapid(line, mid);
  else b_.arc(line, plane_, mid, prog_[ax_.u], prog_[ax_.v], -side_, feed, inverse);
}

// The open moves end at (u, v) now: written to the builder. A line whose new end lies behind
// its start, or an arc that would turn past its start, cannot be cut without gouging.
void CutterComp::flush(double u, double v) {
  const int iu = ax_.u, iv = ax_.v;
  const double su = b_.position()[iu], sv = b_.position()[iv];
  for (Item& it : open_) {
    if (it.kind == Kind::Rapid || it.kind == Kind::Feed) {
      if ((u - su) * it.du + (v - sv) * it.dv < 0.0)
        fail(std::string(it.kind == Kind::Rapid ? "straight traverse" : "straight feed") +
             " in a concave corner cannot be reached by the tool (radius " + mm(radius_mm_) + ") without gouging");
    } else if (it.kind == Kind::Arc) {
      const double a0 = std::atan2(sv - it.cv, su - it.cu);
      double old_sweep = sweep(a0, std::atan2(it.end[iv] - it.cv, it.end[iu] - it.cu), it.rotation);
      if (old_sweep < 1e-12) old_sweep = 2.0 * kPi;  // a full circle
      if (sweep(a0, std::atan2(v - it.cv, u - it.cu), it.rotation) > old_sweep + 1e-9)
        fail("arc move in a concave corner cannot be reached by the tool (radius " + mm(radius_mm_) + ") without gouging");
    }
    if (it.kind != Kind::Dwell) it.end[iu] = u, it.end[iv] = v;
  }
  for (const Item& it : open_) emit(it);
  open_.clear();
}

void CutterComp::emit(const Item& it) {
  switch (it.kind) {
    case Kind::Rapid: b_.rapid(it.line, it.end); break;
    case Kind::Feed: b_.feed(it.line, it.end, it.feed, it.inverse); break;
    case Kind::Arc: b_.arc(it.line, plane_, it.end, it.cu, it.cv, it.rotation, it.feed, it.inverse); break;
    case Kind::Dwell: b_.dwell(it.line, it.dwell_s); break;
  }
}

void CutterComp::push(const Item& it) {
  open_.push_back(it);
  cur_ = it.end;
}

}  // namespace lbr::nc::detail
