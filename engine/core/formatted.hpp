// printf-style formatting into a std::string of whatever length the values need (a fixed
// buffer cut "1e200 s" off mid-number).
#pragma once

#include <cstdio>
#include <string>

namespace snede {

template <class... Values>
std::string formatted(const char* format, Values... values) {
  const int length = std::snprintf(nullptr, 0, format, values...);
  if (length <= 0) return {};
  std::string text(static_cast<std::size_t>(length) + 1, '\0');
  std::snprintf(text.data(), text.size(), format, values...);
  text.pop_back();
  return text;
}

}  // namespace snede
