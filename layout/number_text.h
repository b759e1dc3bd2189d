// A number as error messages print it: nine significant digits, an
// exponent where one reads better ("1e-60", "1.5e+300"), never
// std::to_string's fixed notation (300 digits for 1e300, "0.000000" for
// 1e-60). Nine digits tell any two floats apart.
#pragma once
#include <cstdio>
#include <string>

namespace meshcast {

inline std::string number_text(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

}  // namespace meshcast
