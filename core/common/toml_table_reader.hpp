// TableReader: typed, checked reading of a toml++ table, for the files people write by hand
// (printer profiles, salientd.toml). Every key is looked up by name; whatever is left over is an
// error naming the key and its line. Internal: include it from .cpp files only (it carries
// toml++'s types), which also link tomlplusplus.
#pragma once

#include <toml++/toml.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <set>
#include <sstream>
#include <string>

#include "core/common/input_error.hpp"

namespace salient::core {

inline std::uint64_t line_of(const toml::node& node) {
  return node.source().begin.line;
}

class TableReader {
 public:
  TableReader(const toml::table& table, std::string prefix, const std::string& source)
      : table_(table), prefix_(std::move(prefix)), source_(source) {}

  void number(const char* key, double& out, bool positive = true) {
    if (const toml::node* n = find(key)) {
      const auto v = n->value<double>();
      if (!v) fail(*n, key, "must be a number");
      if (!std::isfinite(*v) || (positive && *v <= 0) || (!positive && *v < 0))
        fail(*n, key, positive ? "must be a positive number" : "must not be negative");
      out = *v;
    }
  }
  // A number within [min, max] (units are the caller's: the message names the key).
  void number(const char* key, double& out, double min, double max) {
    if (const toml::node* n = find(key)) {
      const auto v = n->value<double>();
      if (!v) fail(*n, key, "must be a number");
      if (!(*v >= min && *v <= max))
        fail(*n, key, "must be between " + trimmed(min) + " and " + trimmed(max));
      out = *v;
    }
  }
  template <typename Int>
  void integer(const char* key, Int& out, std::int64_t min, std::int64_t max) {
    if (const toml::node* n = find(key)) {
      const auto v = n->value_exact<std::int64_t>();
      if (!v) fail(*n, key, "must be a whole number");
      if (*v < min || *v > max)
        fail(*n, key, "must be between " + std::to_string(min) + " and " + std::to_string(max));
      out = static_cast<Int>(*v);
    }
  }
  void boolean(const char* key, bool& out) {
    if (const toml::node* n = find(key)) {
      const auto v = n->value_exact<bool>();
      if (!v) fail(*n, key, "must be true or false");
      out = *v;
    }
  }
  void text(const char* key, std::string& out) {
    if (const toml::node* n = find(key)) {
      const auto v = n->value<std::string>();
      if (!v) fail(*n, key, "must be a string");
      out = *v;
    }
  }
  bool has(const char* key) const { return table_.get(key) != nullptr; }
  const toml::table* table(const char* key) {
    const toml::node* n = find(key);
    if (!n) return nullptr;
    if (!n->is_table()) fail(*n, key, "must be a table");
    return n->as_table();
  }
  // `shape` describes what the array holds, for the error (default: an array of tables).
  const toml::array* array(const char* key, const std::string& shape = {}) {
    const toml::node* n = find(key);
    if (!n) return nullptr;
    if (!n->is_array())
      fail(*n, key, shape.empty() ? "must be an array ([[" + std::string(key) + "]])" : "must be " + shape);
    return n->as_array();
  }
  void reject_unknown() const {
    for (const auto& [key, node] : table_)
      if (!seen_.count(std::string(key.str())))
        throw InputError(source_, InputLocation::at_line(line_of(node)),
                         "unknown key '" + prefix_ + std::string(key.str()) + "'");
  }
  [[noreturn]] void fail(const toml::node& n, const char* key, const std::string& what) const {
    throw InputError(source_, InputLocation::at_line(line_of(n)), "'" + prefix_ + key + "' " + what);
  }

 private:
  static std::string trimmed(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
  }
  const toml::node* find(const char* key) {
    seen_.insert(key);
    return table_.get(key);
  }

  const toml::table& table_;
  std::string prefix_;
  const std::string& source_;
  std::set<std::string> seen_;
};

inline void read_section(TableReader& top, const char* name, const std::string& source,
                         const std::function<void(TableReader&)>& fields) {
  if (const toml::table* t = top.table(name)) {
    TableReader r(*t, std::string(name) + ".", source);
    fields(r);
    r.reject_unknown();
  }
}

// Parses TOML text, turning a syntax error into InputError "SOURCE:LINE: …".
inline toml::table parse_toml(std::string_view text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(source, InputLocation::at_line(e.source().begin.line), std::string(e.description()));
  }
}

}  // namespace salient::core
