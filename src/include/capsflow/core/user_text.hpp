#pragma once
// Text the user gave (a scene value, a key, a --set assignment), shortened for an error message: a
// 5 MB string echoed whole would bury the one line it belongs to.
#include <cstddef>
#include <string>
#include <string_view>

namespace capsflow {

// The text itself when it has at most `max` bytes; otherwise its first bytes (cut before a UTF-8
// continuation byte, so no character is split), an ellipsis and the full length in bytes.
inline std::string abbreviate(std::string_view text, std::size_t max = 80) {
  if (text.size() <= max) return std::string(text);
  std::size_t cut = max > 20 ? max - 20 : max;  // room for "… (N bytes)"
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return std::string(text.substr(0, cut)) + "… (" + std::to_string(text.size()) + " bytes)";
}

}  // namespace capsflow
