// Numbers and text as error messages print them.
#pragma once
#include <cstdio>
#include <string>
#include <string_view>

namespace meshcast {

// Nine significant digits, an exponent where one reads better ("1e-60",
// "1.5e+300"), never std::to_string's fixed notation (300 digits for 1e300,
// "0.000000" for 1e-60). Nine digits tell any two floats apart.
inline std::string number_text(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

// Text from an input (a file's key or value, a command-line argument, a
// line of a profile) as a message shows it: at most `limit` bytes of it,
// the length said beside ("... (5000000 bytes)"), and every byte outside
// printable ASCII as \xNN (a NUL would end the message where a C string is
// printed; a control character would garble a terminal).
inline std::string shown_text(std::string_view text, size_t limit = 64) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < limit; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += char(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", c);
      out += escaped;
    }
  }
  if (text.size() > limit) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

}  // namespace meshcast
