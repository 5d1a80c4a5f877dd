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
    std::string m = file + ": " + what;
    if (!value.empty()) m += " (" + value + ")";
    return m;
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
