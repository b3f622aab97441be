#include "key_table.hpp"

#include <cstdlib>

namespace capsflow::scene_detail {

std::string number_text(double v) {
  std::string s = fmt::format("{}", v);  // shortest round trip: what the user wrote, in most cases
  // 1000000000 reads better as 1e9 (when the short form still round-trips).
  if (const std::string g = fmt::format("{:g}", v); g.size() < s.size() && std::strtod(g.c_str(), nullptr) == v) s = g;
  // Exponents without '+' and leading zeros: 1e-09 → 1e-9, 1e+300 → 1e300.
  const auto e = s.find('e');
  if (e == std::string::npos) return s;
  std::string exponent = s.substr(e + 1);
  const bool negative = !exponent.empty() && exponent[0] == '-';
  if (!exponent.empty() && (exponent[0] == '-' || exponent[0] == '+')) exponent.erase(0, 1);
  while (exponent.size() > 1 && exponent[0] == '0') exponent.erase(0, 1);
  return s.substr(0, e + 1) + (negative ? "-" : "") + exponent;
}

}  // namespace capsflow::scene_detail
