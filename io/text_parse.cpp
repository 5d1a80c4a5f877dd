#include "text_parse.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <system_error>

#include "atomic_file.hpp"
#include "errors.hpp"

namespace gs::text {

std::string read_file_bytes(const std::filesystem::path& path, std::size_t max_bytes) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(name, "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name, "not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(name, "cannot stat file", ec.message());
  if (size > max_bytes) throw InputError(name, "file too large", std::to_string(size) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, "cannot open file");
  note_input(path);
  std::string s(size, '\0');
  in.read(s.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::size_t>(in.gcount()) != size) throw InputError(name, "short read");
  return s;
}

std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes) {
  const std::string name = path.string();
  std::string s = read_file_bytes(path, max_bytes);
  // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first field.
  if (s.rfind("\xEF\xBB\xBF", 0) == 0) s.erase(0, 3);
  if (s.find('\0') != std::string::npos)
    throw InputError(name, "binary content in a text file",
                     "NUL byte at offset " + std::to_string(s.find('\0')));
  return s;
}

std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> out;
  std::size_t b = 0;
  while (b < text.size()) {
    std::size_t e = text.find('\n', b);
    if (e == std::string_view::npos) e = text.size();
    std::string_view l = text.substr(b, e - b);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    out.push_back(l);
    b = e + 1;
  }
  return out;
}

std::string_view trim(std::string_view s) {
  const char* ws = " \t\r\n\f\v";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::strchr(" \t\r\f\v", line[i]) && line[i] != '\0') ++i;
    std::size_t j = i;
    while (j < line.size() && !std::strchr(" \t\r\f\v", line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

std::vector<std::string_view> split_csv(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t b = 0;
  while (true) {
    const auto e = line.find(',', b);
    out.push_back(
        trim(line.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b)));
    if (e == std::string_view::npos) break;
    b = e + 1;
  }
  return out;
}

std::vector<std::size_t> column_indices(const std::vector<std::string_view>& header,
                                        const std::vector<std::string_view>& names) {
  std::vector<std::size_t> col(names.size(), header.size());
  for (std::size_t k = 0; k < names.size(); ++k)
    for (std::size_t c = 0; c < header.size(); ++c)
      if (header[c] == names[k]) col[k] = c;
  return col;
}

double to_double(std::string_view tok, const std::string& file, std::size_t line,
                 const std::string& field) {
  double v = 0;
  std::string_view t = tok;
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size())
    throw InputError(file, "line " + std::to_string(line) + ": bad number in " + field,
                     std::string(tok.substr(0, 40)));
  return v;
}

std::int64_t to_int(std::string_view tok, const std::string& file, std::size_t line,
                    const std::string& field) {
  std::int64_t v = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (r.ec == std::errc() && r.ptr == tok.data() + tok.size()) return v;
  // Accept integral values written as floating point (YADE exports ids as doubles).
  const double d = to_double(tok, file, line, field);
  if (d != static_cast<double>(static_cast<std::int64_t>(d)) || std::abs(d) > 9e15)
    throw InputError(file, "line " + std::to_string(line) + ": not an integer in " + field,
                     std::string(tok.substr(0, 40)));
  return static_cast<std::int64_t>(d);
}

}  // namespace gs::text
