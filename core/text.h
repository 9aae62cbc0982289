// Small text helpers shared by the parsers (NRRD headers, OBJ lines, --material specs).
#pragma once

#include <string>
#include <string_view>

namespace eik {

// Whitespace as the C locale's isspace: space, \t, \n, \v, \f, \r.
constexpr bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

// `text` without leading and trailing whitespace (a view into `text`).
constexpr std::string_view trim(std::string_view text) {
  while (!text.empty() && isSpace(text.front())) text.remove_prefix(1);
  while (!text.empty() && isSpace(text.back())) text.remove_suffix(1);
  return text;
}

// `text` in lower case (ASCII only).
std::string lower(std::string_view text);

}  // namespace eik
