// Name tables: an enum's one table of names (std::array of {value, name} pairs, in one .cpp or
// header next to the enum) and the two lookups every such table needs, written once.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>

namespace salient::core {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<E, std::string_view>, N>;

// The name of `value`; `fallback` only for a value missing from the table (a bug).
template <class E, std::size_t N>
constexpr std::string_view name_in(const NameTable<E, N>& table, E value, std::string_view fallback = {}) {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  return fallback;
}

// The value named `name`, or nothing for a name the table does not hold.
template <class E, std::size_t N>
constexpr std::optional<E> value_in(const NameTable<E, N>& table, std::string_view name) {
  for (const auto& [v, n] : table)
    if (n == name) return v;
  return std::nullopt;
}

}  // namespace salient::core
