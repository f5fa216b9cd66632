// RS274/NGC parameters and expressions (ngc_expr.hpp). Operator precedence, the comparison
// tolerance, MOD's sign and ROUND's rounding follow LinuxCNC's interpreter, so that programs
// written for it compute the same numbers here.
#include "ngc_expr.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <sstream>

namespace lbr::nc::detail {

namespace {

constexpr double kEqualTol = 0.0001;  // LinuxCNC's TOLERANCE_EQUAL for EQ / NE
constexpr int kMaxDepth = 100;        // nesting of brackets and parameter references
constexpr double kDeg = std::numbers::pi / 180.0;

bool is_upper(char c) { return c >= 'A' && c <= 'Z'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Binary operators by precedence level: 1 logical, 2 relational, 3 additive, 4 multiplicative, 5 power.
struct Op {
  const char* text;
  int level;
};
constexpr Op kOps[] = {{"**", 5}, {"*", 4}, {"/", 4}, {"MOD", 4}, {"+", 3}, {"-", 3}, {"EQ", 2}, {"NE", 2},
                       {"GT", 2}, {"GE", 2}, {"LT", 2}, {"LE", 2}, {"AND", 1}, {"OR", 1}, {"XOR", 1}};

const Op* op_at(std::string_view s, std::size_t pos) {
  for (const Op& op : kOps)
    if (s.substr(pos).starts_with(op.text)) return &op;
  return nullptr;
}

double apply(std::string_view op, double a, double b) {
  if (op == "**") {
    if (a < 0.0 && b != std::floor(b)) throw ExprError("negative number to a non-integer power");
    return std::pow(a, b);
  }
  if (op == "*") return a * b;
  if (op == "/") {
    if (b == 0.0) throw ExprError("division by zero");
    return a / b;
  }
  if (op == "MOD") {
    if (b == 0.0) throw ExprError("division by zero (MOD)");
    const double r = std::fmod(a, b);
    return r < 0.0 ? r + std::abs(b) : r;
  }
  if (op == "+") return a + b;
  if (op == "-") return a - b;
  if (op == "EQ") return std::abs(a - b) < kEqualTol ? 1.0 : 0.0;
  if (op == "NE") return std::abs(a - b) >= kEqualTol ? 1.0 : 0.0;
  if (op == "GT") return a > b ? 1.0 : 0.0;
  if (op == "GE") return a >= b ? 1.0 : 0.0;
  if (op == "LT") return a < b ? 1.0 : 0.0;
  if (op == "LE") return a <= b ? 1.0 : 0.0;
  if (op == "AND") return (a != 0.0 && b != 0.0) ? 1.0 : 0.0;
  if (op == "OR") return (a != 0.0 || b != 0.0) ? 1.0 : 0.0;
  return ((a != 0.0) != (b != 0.0)) ? 1.0 : 0.0;  // XOR
}

double unary(std::string_view f, double x) {
  if (f == "ABS") return std::abs(x);
  if (f == "ACOS" || f == "ASIN") {
    if (x < -1.0 || x > 1.0) throw ExprError(std::string(f) + " argument out of [-1, 1]");
    return (f == "ACOS" ? std::acos(x) : std::asin(x)) / kDeg;
  }
  if (f == "COS") return std::cos(x * kDeg);
  if (f == "SIN") return std::sin(x * kDeg);
  if (f == "TAN") return std::tan(x * kDeg);
  if (f == "EXP") return std::exp(x);
  if (f == "FIX") return std::floor(x);
  if (f == "FUP") return std::ceil(x);
  if (f == "ROUND") return x < 0.0 ? std::ceil(x - 0.5) : std::floor(x + 0.5);
  if (f == "LN") {
    if (x <= 0.0) throw ExprError("LN of a number <= 0");
    return std::log(x);
  }
  if (f == "SQRT") {
    if (x < 0.0) throw ExprError("SQRT of a negative number");
    return std::sqrt(x);
  }
  throw ExprError("unknown function '" + std::string(f) + "'");
}

void expect(std::string_view s, std::size_t& pos, char c, const char* what) {
  if (pos >= s.size() || s[pos] != c) throw ExprError(std::string("expected '") + c + "' " + what);
  ++pos;
}

double checked(double v) {
  if (!std::isfinite(v) || std::abs(v) > 1e300) throw ExprError("expression value out of range");
  return v;
}

}  // namespace

NormalisedLine normalise_line(std::string_view raw) {
  NormalisedLine out;
  out.code.reserve(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const char c = raw[i];
    if (c == ';') break;
    if (c == '(') {
      const std::size_t close = raw.find(')', i);
      if (close == std::string_view::npos) throw ExprError("unclosed comment '('");
      out.comments.emplace_back(raw.substr(i + 1, close - i - 1));
      i = close;
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\r') continue;
    out.code.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
  }
  return out;
}

// ---- parameters ----------------------------------------------------------------------------

double vacant() { return std::numeric_limits<double>::quiet_NaN(); }
bool is_vacant(double v) { return std::isnan(v); }

Params::Params() : frames_(1) {}

void Params::use_fanuc_variables() {
  fanuc_ = true;
  locals_ = kFanucLocalParams;
  numbered_.assign(numbered_.size(), vacant());
}

double Params::unset() const { return fanuc_ ? vacant() : 0.0; }

double& Params::slot(int n) {
  const auto k = static_cast<std::size_t>(n);
  if (k >= numbered_.size()) numbered_.resize(k + 1, unset());
  return numbered_[k];
}

namespace {
bool fanuc_settable(int n) { return (n >= 1 && n <= kFanucLocalParams) || (n >= 100 && n <= 199) || (n >= 500 && n <= 999); }
std::string fanuc_ranges() { return "(locals #1-#33, common #100-#199 and #500-#999; docs/nc-frontend.md#fanuc-dialect)"; }
}  // namespace

double Params::numbered(int n) const {
  double v = 0.0;
  if (numbered_hook && numbered_hook(n, v)) return v;
  if (fanuc_ && n == 0) return vacant();
  if (fanuc_ && !fanuc_settable(n)) throw ExprError("variable #" + std::to_string(n) + " is not supported " + fanuc_ranges());
  if (n < 1 || n > kMaxNumberedParam)
    throw ExprError("parameter number " + std::to_string(n) + " out of range [1, " + std::to_string(kMaxNumberedParam) + "]");
  const auto k = static_cast<std::size_t>(n);
  return k < numbered_.size() ? numbered_[k] : unset();
}

void Params::set_numbered(int n, double v) {
  if (fanuc_ && !fanuc_settable(n)) throw ExprError("variable #" + std::to_string(n) + " cannot be set " + fanuc_ranges());
  if (n < 1 || n > kMaxNumberedParam)
    throw ExprError("parameter number " + std::to_string(n) + " out of range [1, " + std::to_string(kMaxNumberedParam) + "]");
  slot(n) = v;
}

bool Params::named_exists(const std::string& name) const {
  double v = 0.0;
  if (named_hook && named_hook(name, v)) return true;
  if (!name.empty() && name[0] == '_') return globals_.count(name) != 0;
  return frames_.back().locals.count(name) != 0;
}

double Params::named(const std::string& name) const {
  double v = 0.0;
  if (named_hook && named_hook(name, v)) return v;
  const auto& m = !name.empty() && name[0] == '_' ? globals_ : frames_.back().locals;
  const auto it = m.find(name);
  if (it == m.end()) throw ExprError("named parameter '#<" + name + ">' is not defined");
  return it->second;
}

void Params::set_named(const std::string& name, double v) {
  if (!name.empty() && name[0] == '_') globals_[name] = v;
  else frames_.back().locals[name] = v;
}

void Params::push_frame(const std::vector<double>& args) {
  Frame f;
  (void)slot(locals_);
  for (int i = 0; i < locals_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    f.saved[k] = numbered_[k + 1];
    numbered_[k + 1] = k < args.size() ? args[k] : unset();
  }
  frames_.push_back(std::move(f));
}

void Params::pop_frame() {
  if (frames_.size() <= 1) return;
  for (std::size_t k = 0; k < static_cast<std::size_t>(locals_); ++k) numbered_[k + 1] = frames_.back().saved[k];
  frames_.pop_back();
}

// ---- expressions ---------------------------------------------------------------------------

bool ExprReader::number_starts(std::string_view s, std::size_t pos) {
  return pos < s.size() && (is_digit(s[pos]) || (s[pos] == '.' && pos + 1 < s.size() && is_digit(s[pos + 1])));
}

double ExprReader::number(std::string_view s, std::size_t& pos) {
  const std::size_t start = pos;
  std::size_t digits = 0;
  while (pos < s.size() && is_digit(s[pos])) ++pos, ++digits;
  if (pos < s.size() && s[pos] == '.') {
    ++pos;
    while (pos < s.size() && is_digit(s[pos])) ++pos, ++digits;
  }
  if (digits == 0) throw ExprError("expected a number");
  const std::string text(s.substr(start, pos - start));
  return checked(std::strtod(text.c_str(), nullptr));
}

double ExprReader::value(std::string_view s, std::size_t& pos) {
  if (pos >= s.size()) throw ExprError("expected a value at the end of the line");
  if (++depth_ > kMaxDepth) throw ExprError("expression nested too deeply");
  double v = 0.0;
  const char c = s[pos];
  if (c == '+' || c == '-') {
    ++pos;
    v = value(s, pos);
    if (params_.fanuc() && is_vacant(v)) v = 0.0;  // <vacant> in arithmetic is 0
    if (c == '-') v = -v;
  } else if (c == '[') {
    v = bracketed(s, pos);
  } else if (c == '#') {
    v = parameter(s, pos);
  } else if (is_upper(c)) {
    v = function(s, pos);
  } else {
    v = number(s, pos);
  }
  --depth_;
  return v;
}

double ExprReader::bracketed(std::string_view s, std::size_t& pos) {
  expect(s, pos, '[', "to open an expression");
  const double v = binary(s, pos, 1);
  expect(s, pos, ']', "to close the expression");
  return v;
}

// Precedence climbing: operands of level L are expressions of operators above L.
double ExprReader::binary(std::string_view s, std::size_t& pos, int level) {
  if (level > 5) return value(s, pos);
  double left = binary(s, pos, level + 1);
  while (pos < s.size()) {
    const Op* op = op_at(s, pos);
    if (op == nullptr || op->level != level) break;
    pos += std::string_view(op->text).size();
    const double right = binary(s, pos, level + 1);
    left = checked(operate(op->text, left, right));
  }
  return left;
}

// Fanuc's <vacant>: EQ / NE tell it from every number (also 0); elsewhere it is 0.
double ExprReader::operate(std::string_view op, double a, double b) const {
  if (!params_.fanuc()) return apply(op, a, b);
  if ((op == "EQ" || op == "NE") && (is_vacant(a) || is_vacant(b))) {
    const bool equal = is_vacant(a) && is_vacant(b);
    return (op == "EQ") == equal ? 1.0 : 0.0;
  }
  return apply(op, is_vacant(a) ? 0.0 : a, is_vacant(b) ? 0.0 : b);
}

std::string ExprReader::param_name(std::string_view s, std::size_t& pos) {
  expect(s, pos, '<', "to open a parameter name");
  const std::size_t close = s.find('>', pos);
  if (close == std::string_view::npos) throw ExprError("parameter name without closing '>'");
  std::string name(s.substr(pos, close - pos));
  if (name.empty()) throw ExprError("empty parameter name '#<>'");
  pos = close + 1;
  return name;
}

int ExprReader::param_number(std::string_view s, std::size_t& pos) {
  const double v = value(s, pos);
  const double r = std::nearbyint(v);
  const int lowest = params_.fanuc() ? 0 : 1;  // Fanuc #0: <vacant>
  if (!(std::abs(v - r) <= 1e-4) || r < lowest || r > kMaxNumberedParam)
    throw ExprError("parameter number " + [&] {
      std::ostringstream o;
      o << v;
      return o.str();
    }() + " is not an integer in [" + std::to_string(lowest) + ", " +
                    std::to_string(kMaxNumberedParam) + "]");
  return static_cast<int>(r);
}

double ExprReader::parameter(std::string_view s, std::size_t& pos) {
  expect(s, pos, '#', "");
  if (pos < s.size() && s[pos] == '<') return params_.named(param_name(s, pos));
  return params_.numbered(param_number(s, pos));
}

double ExprReader::function(std::string_view s, std::size_t& pos) {
  std::size_t e = pos;
  while (e < s.size() && is_upper(s[e])) ++e;
  const std::string_view f = s.substr(pos, e - pos);
  pos = e;
  if (f == "EXISTS") {
    expect(s, pos, '[', "after EXISTS");
    expect(s, pos, '#', "in EXISTS[#<name>]");
    const bool ex = params_.named_exists(param_name(s, pos));
    expect(s, pos, ']', "to close EXISTS[");
    return ex ? 1.0 : 0.0;
  }
  if (pos >= s.size() || s[pos] != '[')
    throw ExprError("unexpected '" + std::string(f) + "' (expected a number, a parameter or an expression)");
  if (params_.fanuc()) return fanuc_function(f, s, pos);
  const double x = bracketed(s, pos);
  if (f == "ATAN") {
    expect(s, pos, '/', "in ATAN[y]/[x]");
    const double xd = bracketed(s, pos);
    return std::atan2(x, xd) / kDeg;
  }
  return checked(unary(f, x));
}

// Fanuc's functions: one or two arguments ("ATAN[y]/[x]", "ATAN[y,x]", "POW[a,b]"); FIX and
// FUP round towards and away from zero; ATAN answers in [0, 360); <vacant> arguments are 0.
double ExprReader::fanuc_function(std::string_view f, std::string_view s, std::size_t& pos) {
  expect(s, pos, '[', "to open the argument");
  auto arg = [&] {
    const double v = binary(s, pos, 1);
    return is_vacant(v) ? 0.0 : v;
  };
  const double x = arg();
  if (f == "ATAN" || f == "POW") {
    double y = 0.0;
    const bool two = pos < s.size() && s[pos] == ',';
    if (two) ++pos, y = arg();
    expect(s, pos, ']', "to close the argument");
    if (f == "POW") {
      if (!two) throw ExprError("POW needs two arguments: POW[base,exponent]");
      return checked(apply("**", x, y));
    }
    if (!two && (pos >= s.size() || s[pos] != '/')) return std::atan(x) / kDeg;  // ATAN[x]: (-90, 90)
    if (!two) {
      ++pos;
      y = bracketed(s, pos);
    }
    const double deg = std::atan2(x, is_vacant(y) ? 0.0 : y) / kDeg;
    return deg < 0.0 ? deg + 360.0 : deg;
  }
  expect(s, pos, ']', "to close the argument");
  if (f == "FIX") return std::trunc(x);
  if (f == "FUP") return x < 0.0 ? -std::ceil(-x) : std::ceil(x);
  if (f == "BIN" || f == "BCD") {
    if (x < 0.0 || x > 99999999.0 || x != std::floor(x)) throw ExprError(std::string(f) + " needs an integer in [0, 99999999]");
    auto n = static_cast<unsigned long long>(x);
    unsigned long long out = 0, scale = 1;
    for (; n > 0; scale *= f == "BIN" ? 10 : 16) {
      const unsigned long long digit = f == "BIN" ? n % 16 : n % 10;
      if (digit > 9) throw ExprError("BIN of a value that is not BCD");
      out += digit * scale;
      n /= f == "BIN" ? 16 : 10;
    }
    return static_cast<double>(out);
  }
  return checked(unary(f, x));
}

ParamAssign ExprReader::assignment(std::string_view s, std::size_t& pos) {
  ParamAssign a;
  expect(s, pos, '#', "");
  if (pos < s.size() && s[pos] == '<') {
    if (params_.fanuc()) throw ExprError("named parameters '#<...>' are not part of the fanuc dialect");
    a.name = param_name(s, pos);
  } else {
    a.number = param_number(s, pos);
  }
  expect(s, pos, '=', "in a parameter setting");
  a.value = params_.fanuc() ? binary(s, pos, 1) : value(s, pos);
  return a;
}

}  // namespace lbr::nc::detail
