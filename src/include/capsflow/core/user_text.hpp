#pragma once
// Text the user gave (a scene value, a key, a --set assignment), shortened for an error message: a
// 5 MB string echoed whole would bury the one line it belongs to; a line break in it would make
// the message two lines, so control characters are echoed escaped (\n, \r, \t, \x1b).
#include <cstddef>
#include <string>
#include <string_view>

namespace capsflow {

// `text` with its control characters (bytes below 0x20, and 0x7f) written as escapes.
inline std::string escape_control(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7f) {
      const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += c;
    }
  }
  return out;
}

// The text itself (control characters escaped) when it has at most `max` bytes; otherwise its
// first bytes (cut before a UTF-8 continuation byte, so no character is split), an ellipsis and
// the full length in bytes.
inline std::string abbreviate(std::string_view text, std::size_t max = 80) {
  if (text.size() <= max) return escape_control(text);
  std::size_t cut = max > 20 ? max - 20 : max;  // room for "… (N bytes)"
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return escape_control(text.substr(0, cut)) + "… (" + std::to_string(text.size()) + " bytes)";
}

}  // namespace capsflow
