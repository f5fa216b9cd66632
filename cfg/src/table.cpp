#include "cfg/table.hpp"

#include <cmath>
#include <cstdint>
#include <sstream>

namespace lbr::cfg {

toml::table parse(const std::string& text, const std::string& file) {
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw ConfigError(file + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
}

Table::Table(const toml::table& t, std::string path, const std::string& file) : t_(t), path_(std::move(path)), file_(file) {}

void Table::fail(const toml::node* n, const std::string& key, const std::string& msg) const {
  const auto line = n != nullptr ? n->source().begin.line : t_.source().begin.line;
  throw ConfigError(file_ + ":" + std::to_string(line) + ": " + qualified(key) + ": " + msg);
}

std::string Table::qualified(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

void Table::only_for(const std::string& key, bool allowed, const std::string& kinds) const {
  if (t_.get(key) != nullptr && !allowed) fail(t_.get(key), key, "only for machine kind " + kinds);
}

const toml::node* Table::get(const std::string& key) {
  used_.insert(key);
  return t_.get(key);
}

double Table::number(const std::string& key, double def, double lo, double hi, const char* unit) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  double v = 0.0;
  if (auto f = n->value<double>()) v = *f;
  else fail(n, key, std::string("expected a number [") + unit + "]");
  if (!std::isfinite(v) || v < lo || v > hi) {
    std::ostringstream m;
    m << "expected a number in [" << lo << ", " << hi << "] " << unit << ", got " << v;
    fail(n, key, m.str());
  }
  return v;
}

double Table::required_number(const std::string& key, double lo, double hi, const char* unit) {
  if (t_.get(key) == nullptr) fail(nullptr, key, std::string("missing (a number [") + unit + "] is required)");
  return number(key, 0.0, lo, hi, unit);
}

long Table::integer(const std::string& key, long def, long lo, long hi) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  const auto v = n->value_exact<std::int64_t>();
  if (!v || *v < lo || *v > hi) fail(n, key, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<long>(*v);
}

std::string Table::string(const std::string& key, const std::string& def) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  const auto v = n->value_exact<std::string>();
  if (!v) fail(n, key, "expected a string");
  return *v;
}

bool Table::boolean(const std::string& key, bool def) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  const auto v = n->value_exact<bool>();
  if (!v) fail(n, key, "expected true or false");
  return *v;
}

std::vector<double> Table::numbers(const std::string& key, std::size_t count, const char* unit) {
  const toml::node* n = get(key);
  if (n == nullptr) fail(nullptr, key, "missing (an array of " + std::to_string(count) + " numbers [" + unit + "] is required)");
  const toml::array* a = n->as_array();
  if (a == nullptr || a->size() != count) fail(n, key, "expected an array of " + std::to_string(count) + " numbers [" + unit + "]");
  std::vector<double> out;
  for (const toml::node& e : *a) {
    const auto v = e.value<double>();
    if (!v || !std::isfinite(*v)) fail(&e, key, std::string("expected numbers [") + unit + "]");
    out.push_back(*v);
  }
  return out;
}

void Table::triple(const std::string& key, std::array<double, 3>& out, double lo, double hi, const char* unit) {
  if (t_.get(key) == nullptr) {
    used_.insert(key);
    return;
  }
  const auto v = numbers(key, 3, unit);
  for (std::size_t i = 0; i < 3; ++i) {
    if (v[i] < lo || v[i] > hi) {
      std::ostringstream msg;
      msg << "expected numbers in [" << lo << ", " << hi << "] " << unit << ", got " << v[i];
      fail(t_.get(key), key, msg.str());
    }
    out[i] = v[i];
  }
}

const toml::table* Table::table(const std::string& key) {
  const toml::node* n = get(key);
  if (n == nullptr) return nullptr;
  if (!n->is_table()) fail(n, key, "expected a table [" + qualified(key) + "]");
  return n->as_table();
}

std::vector<const toml::table*> Table::tables(const std::string& key) {
  std::vector<const toml::table*> out;
  const toml::node* n = get(key);
  if (n == nullptr) return out;
  const toml::array* a = n->as_array();
  if (a == nullptr) fail(n, key, "expected an array of tables [[" + qualified(key) + "]]");
  for (const toml::node& e : *a) {
    if (!e.is_table()) fail(&e, key, "expected [[" + qualified(key) + "]] tables");
    out.push_back(e.as_table());
  }
  return out;
}

void Table::reject_unknown() const {
  for (const auto& [k, v] : t_) {
    const std::string key(k.str());
    if (!used_.count(key)) fail(&v, key, "unknown key");
  }
}

}  // namespace lbr::cfg
