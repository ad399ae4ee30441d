// An enum's values with the names users write for them, in one table that both directions
// read: a new value is one entry, its parsing, printing and error message follow.
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace snede {

template <class Enum, std::size_t N>
using EnumNames = std::array<std::pair<Enum, std::string_view>, N>;

// One entry of a table: `std::array names{named(Kind::a, "a"), named(Kind::b, "b")}`.
template <class Enum>
constexpr std::pair<Enum, std::string_view> named(Enum value, std::string_view name) {
  return {value, name};
}

// The value called `name`; else std::invalid_argument "<what> must be 'a', 'b' or 'c', got '<name>'".
template <class Enum, std::size_t N>
Enum enum_value(const EnumNames<Enum, N>& names, const std::string& what, std::string_view name) {
  for (const auto& [value, text] : names)
    if (text == name) return value;
  std::string choices;
  for (std::size_t i = 0; i < N; ++i)
    choices += (i == 0 ? "'" : i + 1 == N ? " or '" : ", '") + std::string(names[i].second) + "'";
  throw std::invalid_argument(what + " must be " + choices + ", got '" + std::string(name) + "'");
}

// The name of `value`; std::logic_error for a value the table leaves out.
template <class Enum, std::size_t N>
std::string enum_name(const EnumNames<Enum, N>& names, Enum value) {
  for (const auto& [known, text] : names)
    if (known == value) return std::string(text);
  throw std::logic_error("an enum value without a name: " + std::to_string(static_cast<long long>(value)));
}

}  // namespace snede
