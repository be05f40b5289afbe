// Numbers in messages and reports: the shortest "%g"-style text (std::to_string prints 1e300 as
// 301 digits and 0.1 as 0.100000).
#pragma once
#include <cstdio>
#include <string>

namespace exotwin {

// v with `significant` significant digits ("%.*g").
inline std::string NumberText(double v, int significant = 6) {
  char b[40];
  std::snprintf(b, sizeof(b), "%.*g", significant, v);
  return b;
}

// v formatted by one printf conversion of a double (e.g. "%.2f", "%+.1f %%"); longer text is cut at
// 63 characters.
inline std::string FormatNumber(const char* printf_format, double v) {
  char b[64];
  std::snprintf(b, sizeof(b), printf_format, v);
  return b;
}

}  // namespace exotwin
