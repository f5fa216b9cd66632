// cfg/table.hpp — reading one table of a TOML configuration file (a machine profile).
//
// Each module parses its own tables with a cfg::Table (geom: [stock], [lbr]; kin and nc:
// [machine]; motion: [[tool]]; hal and sched: [live], [threads]; nc: [nc]; gfx: [render]);
// app/ composes them into its profile. A Table remembers which keys were read, so that after
// every reader of a table has run, reject_unknown() reports a key nobody read (a typo) with
// its line. Several modules may read the same table ([machine]).
//
// Setup code: allocates and throws ConfigError("file:line: table.key: what was expected").
#pragma once

#include <array>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "cfg/error.hpp"

namespace lbr::cfg {

// Parses TOML text; `file` names it in messages. Throws ConfigError("file:line: ...").
[[nodiscard]] toml::table parse(const std::string& text, const std::string& file);

class Table {
 public:
  // `path` is the table's dotted name in messages ("" for the root, "live.axis", ...);
  // `file` must outlive the Table.
  Table(const toml::table& t, std::string path, const std::string& file);

  // Throws ConfigError "file:line: path.key: msg" with the line of `n` (the table's line if null).
  [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& msg) const;
  [[nodiscard]] std::string qualified(const std::string& key) const;
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] const toml::table& raw() const noexcept { return t_; }
  // The key's node without marking it read (null when absent).
  [[nodiscard]] const toml::node* peek(const std::string& key) const { return t_.get(key); }
  // Fails at `key` when it is present and `allowed` is false ("only for machine kind KINDS").
  void only_for(const std::string& key, bool allowed, const std::string& kinds) const;

  // Typed keys; each marks the key read. `def` when absent; out of [lo, hi] fails.
  const toml::node* get(const std::string& key);
  double number(const std::string& key, double def, double lo, double hi, const char* unit);
  double required_number(const std::string& key, double lo, double hi, const char* unit);
  long integer(const std::string& key, long def, long lo, long hi);
  std::string string(const std::string& key, const std::string& def);
  bool boolean(const std::string& key, bool def);
  // An array of exactly `count` finite numbers; required.
  std::vector<double> numbers(const std::string& key, std::size_t count, const char* unit);
  // Three numbers in [lo, hi]; `out` unchanged when the key is absent.
  void triple(const std::string& key, std::array<double, 3>& out, double lo, double hi, const char* unit);
  // A sub-table [path.key], or null when absent.
  const toml::table* table(const std::string& key);
  // The tables of an array of tables [[path.key]] (empty when absent).
  std::vector<const toml::table*> tables(const std::string& key);

  // Fails at the first key no reader asked for.
  void reject_unknown() const;

 private:
  const toml::table& t_;
  std::string path_;
  const std::string& file_;
  std::set<std::string> used_;
};

}  // namespace lbr::cfg
