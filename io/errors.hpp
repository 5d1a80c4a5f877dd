// Errors raised at input/output boundaries. The CLI prints what() as
// "error: FILE: what (value)" and exits with code 2.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace gs {

/// Bad or unreadable input. Message form: "FILE: what (value)".
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& what, const std::string& value = {})
      : std::runtime_error(compose(file, what, value)) {}

 private:
  static std::string compose(const std::string& file, const std::string& what,
                             const std::string& value) {
    std::string m = printable(file) + ": " + printable(what);
    if (!value.empty()) m += " (" + printable(value.substr(0, 200)) + ")";
    return m;
  }
  // One line whatever the input holds: control and non-ASCII bytes as \xNN.
  static std::string printable(const std::string& s) {
    static const char* hex = "0123456789abcdef";
    std::string out;
    out.reserve(s.size());
    for (unsigned char c : s) {
      if ((c >= 0x20 && c != 0x7f)) {  // printable ASCII and UTF-8 bytes
        out += static_cast<char>(c);
      } else {
        out += "\\x";
        out += hex[c >> 4];
        out += hex[c & 15];
      }
    }
    return out;
  }
};

/// Formats a number for an error message with full precision.
template <class T>
std::string value_str(const T& v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

}  // namespace gs
