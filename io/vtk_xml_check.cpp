#include "vtk_xml_check.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxDepth = 64;
// zlib's deflate compresses at most 1032:1 (LZ4 255:1): no count may claim more values than
// this many times the bytes the file holds.
constexpr std::uint64_t kMaxRatio = 1100;

struct Tag {
  std::string name;
  std::map<std::string, std::string> attrs;
  bool self_closing = false;
  std::size_t end = 0;  // index just past '>'
};

std::string attr(const Tag& t, const std::string& k) {
  const auto it = t.attrs.find(k);
  return it == t.attrs.end() ? std::string() : it->second;
}

// Parses the tag opening at xml[at] == '<' (not a closing tag, comment or declaration); nullopt
// when the file ends inside it.
std::optional<Tag> parse_tag(std::string_view xml, std::size_t at) {
  Tag t;
  std::size_t i = at + 1;
  auto is_name = [](char c) {
    return c != '>' && c != '/' && c != '=' && c != ' ' && c != '\t' && c != '\r' && c != '\n';
  };
  while (i < xml.size() && is_name(xml[i])) t.name += xml[i++];
  while (i < xml.size()) {
    const char c = xml[i];
    if (c == '>') {
      t.end = i + 1;
      return t;
    }
    if (c == '/') {
      t.self_closing = true;
      ++i;
      continue;
    }
    if (!is_name(c)) {
      ++i;
      continue;
    }
    std::string key;
    while (i < xml.size() && is_name(xml[i])) key += xml[i++];
    while (i < xml.size() && (xml[i] == ' ' || xml[i] == '\t' || xml[i] == '\r' || xml[i] == '\n'))
      ++i;
    if (i >= xml.size() || xml[i] != '=') continue;
    ++i;
    while (i < xml.size() && (xml[i] == ' ' || xml[i] == '\t' || xml[i] == '\r' || xml[i] == '\n'))
      ++i;
    if (i >= xml.size()) return std::nullopt;
    const char q = xml[i];
    if (q != '"' && q != '\'') continue;
    const auto close = xml.find(q, i + 1);
    if (close == std::string_view::npos) return std::nullopt;
    t.attrs[key] = std::string(xml.substr(i + 1, close - i - 1));
    t.self_closing = false;
    i = close + 1;
  }
  return std::nullopt;
}

// The XML part of the file: all of it, or up to a little past `<AppendedData` (binary follows).
std::string read_xml_part(std::ifstream& in, const std::string& name) {
  std::string xml;
  std::string chunk(1 << 20, '\0');
  std::size_t tail_wanted = 0;
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got == 0) break;
    const std::size_t from = xml.size() >= 16 ? xml.size() - 16 : 0;
    xml.append(chunk.data(), got);
    if (tail_wanted > 0) break;
    if (xml.find("<AppendedData", from) != std::string::npos) tail_wanted = 1;
  }
  if (in.bad()) throw InputError(name, "cannot read file");
  return xml;
}

std::uint64_t swap_bytes(std::uint64_t v, std::size_t n) {
  std::uint64_t r = 0;
  for (std::size_t k = 0; k < n; ++k) r |= ((v >> (8 * k)) & 0xff) << (8 * (n - 1 - k));
  return r;
}

int b64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// The first `bytes` bytes of a base64 stream (whitespace skipped); fewer when it ends early.
std::string b64_prefix(std::string_view s, std::size_t bytes) {
  std::string out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    if (out.size() >= bytes) break;
    if (c == '=') break;
    const int v = b64_value(c);
    if (v < 0) continue;
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xff);
    }
  }
  return out;
}

std::size_t type_size(const std::string& t) {
  if (t == "Int8" || t == "UInt8") return 1;
  if (t == "Int16" || t == "UInt16") return 2;
  if (t == "Int32" || t == "UInt32" || t == "Float32") return 4;
  if (t == "Int64" || t == "UInt64" || t == "Float64") return 8;
  return 0;  // String, Bit, ...: not checked
}

// A non-negative integer attribute, whole.
std::optional<std::uint64_t> parse_count(std::string_view v) {
  v = text::trim(v);
  std::uint64_t n = 0;
  const auto r = std::from_chars(v.data(), v.data() + v.size(), n);
  if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size()) return std::nullopt;
  return n;
}

// Where a DataArray's header words come from: the file (appended raw) or a base64 stream.
struct Source {
  std::ifstream* in = nullptr;
  std::uint64_t pos = 0;        // appended raw: file offset of the header
  std::string_view b64;         // base64: the characters (inline content or from the file)
  std::uint64_t available = 0;  // bytes the data can occupy at most
};

class Checker {
 public:
  Checker(const fs::path& path) : name_(path.string()) {}

  void run(const fs::path& path) {
    std::error_code ec;
    size_ = fs::file_size(path, ec);
    if (ec) return;  // (the reader reports it)
    in_.open(path, std::ios::binary);
    if (!in_) return;
    const std::string xml = read_xml_part(in_, name_);
    in_.clear();
    scan(xml);
  }

 private:
  [[noreturn]] void fail(const std::string& what, const std::string& value) const {
    throw InputError(name_, what, value);
  }

  void scan(const std::string& xml) {
    std::vector<std::string> stack;
    std::size_t i = 0;
    while ((i = xml.find('<', i)) != std::string::npos) {
      const std::string_view rest = std::string_view(xml).substr(i);
      auto skip_to = [&](const char* end) {
        const auto e = xml.find(end, i);
        return e == std::string::npos ? std::string::npos : e + std::strlen(end);
      };
      if (rest.rfind("<?", 0) == 0) {
        i = skip_to("?>");
      } else if (rest.rfind("<!--", 0) == 0) {
        i = skip_to("-->");
      } else if (rest.rfind("<![CDATA[", 0) == 0) {
        i = skip_to("]]>");
      } else if (rest.rfind("<!", 0) == 0 || rest.rfind("</", 0) == 0) {
        if (rest.rfind("</", 0) == 0 && !stack.empty()) stack.pop_back();
        i = skip_to(">");
      } else {
        const auto tag = parse_tag(xml, i);
        if (!tag) return;  // cut inside a tag: VTK's parser reports it
        i = tag->end;
        if (stack.size() + 1 > kMaxDepth)
          fail("XML elements nested too deep",
               "more than " + std::to_string(kMaxDepth) + " levels");
        on_element(*tag, stack.empty() ? std::string() : stack.back(), xml);
        if (tag->name == "AppendedData") {
          const auto us = xml.find('_', tag->end);
          if (us != std::string::npos) check_appended(xml, us + 1, attr(*tag, "encoding"));
          return;
        }
        if (!tag->self_closing) stack.push_back(tag->name);
      }
      if (i == std::string::npos) return;
    }
  }

  void on_element(const Tag& t, const std::string& parent, const std::string& xml) {
    if (t.name == "VTKFile") {
      header_bytes_ = attr(t, "header_type") == "UInt64" ? 8 : 4;
      big_endian_ = attr(t, "byte_order") == "BigEndian";
      compressed_ = !attr(t, "compressor").empty();
    } else if (t.name == "Piece") {
      counts_.clear();
      for (const auto& [k, v] : t.attrs) {
        if (k.rfind("NumberOf", 0) != 0) continue;
        const auto n = parse_count(v);
        if (!n) fail("Piece " + k + " is not a non-negative integer", v);
        if (*n / kMaxRatio > size_) fail("Piece " + k + " exceeds what the file can hold", v);
        counts_[k] = *n;
      }
    } else if (t.name == "DataArray") {
      on_data_array(t, parent, xml);
    }
  }

  std::optional<std::uint64_t> count(const char* k) const {
    const auto it = counts_.find(k);
    return it == counts_.end() ? std::nullopt : std::optional<std::uint64_t>(it->second);
  }

  // Tuples the DataArray must hold, where the counts say.
  std::optional<std::uint64_t> expected_tuples(const Tag& t, const std::string& parent) const {
    const std::string nm = attr(t, "Name");
    if (parent == "Points" || parent == "PointData") return count("NumberOfPoints");
    if (parent == "CellData") {
      if (const auto c = count("NumberOfCells")) return c;
      std::uint64_t s = 0;
      bool any = false;
      for (const char* k : {"NumberOfVerts", "NumberOfLines", "NumberOfStrips", "NumberOfPolys"})
        if (const auto c = count(k)) {
          s += *c;
          any = true;
        }
      return any ? std::optional<std::uint64_t>(s) : std::nullopt;
    }
    if (parent == "Cells" && (nm == "offsets" || nm == "types")) return count("NumberOfCells");
    if (nm == "offsets" &&
        (parent == "Verts" || parent == "Lines" || parent == "Strips" || parent == "Polys"))
      return count(("NumberOf" + parent).c_str());
    if (parent == "FieldData" && t.attrs.count("NumberOfTuples")) {
      const auto n = parse_count(attr(t, "NumberOfTuples"));
      if (!n || *n / kMaxRatio > size_)
        fail("DataArray " + nm + " NumberOfTuples is not a count the file can hold",
             attr(t, "NumberOfTuples"));
      return n;
    }
    return std::nullopt;
  }

  struct Pending {
    std::string label;
    std::optional<std::uint64_t> bytes;  // the data's size, when the counts fix it
    std::uint64_t offset = 0;
  };

  void on_data_array(const Tag& t, const std::string& parent, const std::string& xml) {
    const std::string label = "DataArray " + (t.attrs.count("Name") ? attr(t, "Name") : parent);
    std::uint64_t comps = 1;
    if (t.attrs.count("NumberOfComponents")) {
      const auto c = parse_count(attr(t, "NumberOfComponents"));
      if (!c || *c < 1 || *c > 65536)
        fail(label + " NumberOfComponents is not a positive integer",
             attr(t, "NumberOfComponents"));
      comps = *c;
    }
    // VTK dereferences the array it failed to create for an unknown type (SIGSEGV).
    static const char* known[] = {"Int8",   "UInt8", "Int16",  "UInt16",  "Int32",
                                  "UInt32", "Int64", "UInt64", "Float32", "Float64",
                                  "String", "Bit",   "IdType", "Char"};
    const std::string type = attr(t, "type");
    if (std::find(std::begin(known), std::end(known), type) == std::end(known))
      fail(label + " has an unknown type", type.empty() ? "none" : type);
    const std::size_t ts = type_size(type);
    const auto tuples = expected_tuples(t, parent);
    std::optional<std::uint64_t> values;
    if (tuples && ts > 0) values = *tuples * comps;
    const std::string format = attr(t, "format");
    if (format == "ascii") {
      if (!values || t.self_closing) return;
      const auto e = xml.find('<', t.end);
      const std::string_view content =
          std::string_view(xml).substr(t.end, (e == std::string::npos ? xml.size() : e) - t.end);
      const std::size_t n = text::split_ws(content).size();
      if (n != *values)
        fail(label + " holds a different number of values than declared",
             std::to_string(n) + " values, expected " + std::to_string(*values));
    } else if (format == "binary") {
      if (t.self_closing) return;
      const auto e = xml.find('<', t.end);
      const std::string_view content =
          std::string_view(xml).substr(t.end, (e == std::string::npos ? xml.size() : e) - t.end);
      Source src;
      src.b64 = content;
      src.available = content.size();
      check_data(label, values ? std::optional<std::uint64_t>(*values * ts) : std::nullopt, src);
    } else if (format == "appended") {
      const auto off = parse_count(attr(t, "offset"));
      if (!off) fail(label + " offset is not a non-negative integer", attr(t, "offset"));
      pending_.push_back(
          {label, values ? std::optional<std::uint64_t>(*values * ts) : std::nullopt, *off});
    }
  }

  void check_appended(const std::string& xml, std::size_t start, const std::string& encoding) {
    for (const auto& p : pending_) {
      if (p.offset > size_ || start + p.offset > size_)
        fail(p.label + " offset is past the end of the file", std::to_string(p.offset));
      Source src;
      const std::uint64_t at = start + p.offset;
      src.available = size_ - at;
      std::string b64;
      if (encoding == "base64") {
        // Enough characters for the largest header we read (checked against the file below).
        b64 = chars_at(at, xml);
        src.b64 = b64;
      } else {
        src.in = &in_;
        src.pos = at;
      }
      check_data(p.label, p.bytes, src);
    }
  }

  // Up to 4 MiB of base64 characters at file offset `at` (the header of a compressed array).
  std::string chars_at(std::uint64_t at, const std::string& xml) {
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(size_ - at, 4 << 20));
    if (at + want <= xml.size()) return xml.substr(static_cast<std::size_t>(at), want);
    std::string s(want, '\0');
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(s.data(), static_cast<std::streamsize>(want));
    s.resize(static_cast<std::size_t>(std::max<std::streamsize>(in_.gcount(), 0)));
    return s;
  }

  // `count` header words from the source; nullopt when the file ends first.
  std::optional<std::vector<std::uint64_t>> words(const Source& s, std::uint64_t first,
                                                  std::uint64_t count) {
    const std::size_t hb = header_bytes_;
    std::string raw;
    const std::uint64_t bytes = (first + count) * hb;
    if (s.in) {
      if (bytes > s.available) return std::nullopt;
      raw.assign(static_cast<std::size_t>(bytes), '\0');
      s.in->clear();
      s.in->seekg(static_cast<std::streamoff>(s.pos));
      s.in->read(raw.data(), static_cast<std::streamsize>(bytes));
      if (static_cast<std::uint64_t>(s.in->gcount()) != bytes) return std::nullopt;
    } else {
      raw = b64_prefix(s.b64, static_cast<std::size_t>(bytes));
      if (raw.size() < bytes) return std::nullopt;
    }
    std::vector<std::uint64_t> w;
    for (std::uint64_t k = first; k < first + count; ++k) {
      std::uint64_t v = 0;
      for (std::size_t b = 0; b < hb; ++b)
        v |= static_cast<std::uint64_t>(static_cast<unsigned char>(raw[k * hb + b])) << (8 * b);
      w.push_back(big_endian_ ? swap_bytes(v, hb) : v);
    }
    return w;
  }

  void check_data(const std::string& label, std::optional<std::uint64_t> bytes, const Source& s) {
    const std::uint64_t hb = header_bytes_;
    auto mismatch = [&](std::uint64_t got) {
      fail(label + " holds a different number of bytes than declared",
           std::to_string(got) + " bytes, expected " + std::to_string(*bytes));
    };
    if (!compressed_) {
      const auto w = words(s, 0, 1);
      if (!w) return;  // (VTK reports the short file)
      if (bytes && (*w)[0] != *bytes) mismatch((*w)[0]);
      if ((*w)[0] > s.available) fail(label + " runs past the end of the file", label);
      return;
    }
    const auto h = words(s, 0, 3);
    if (!h) return;
    const std::uint64_t nb = (*h)[0], bs = (*h)[1], last = (*h)[2];
    if (nb > s.available / hb)
      fail(label + " compression header claims more blocks than the file holds",
           std::to_string(nb) + " blocks");
    if (bs > kMaxRatio * s.available + 65536 || last > bs)
      fail(label + " compression header has a bad block size",
           std::to_string(bs) + ", last " + std::to_string(last));
    const std::uint64_t total = nb == 0 ? 0 : (nb - 1) * bs + (last == 0 ? bs : last);
    if (bytes && total != *bytes) mismatch(total);
    if (total / kMaxRatio > s.available)
      fail(label + " compression header claims more data than the file can hold",
           std::to_string(total) + " bytes");
    if (nb == 0) return;
    const auto sizes = words(s, 3, nb);
    if (!sizes) fail(label + " compression header runs past the end of the file", label);
    std::uint64_t sum = 0;
    for (const auto c : *sizes) {
      if (c > s.available)
        fail(label + " compressed block larger than the file", std::to_string(c));
      sum += c;
    }
    if (sum > s.available)
      fail(label + " compressed blocks run past the end of the file",
           std::to_string(sum) + " bytes");
  }

  std::string name_;
  std::uint64_t size_ = 0;
  std::ifstream in_;
  std::size_t header_bytes_ = 4;
  bool big_endian_ = false, compressed_ = false;
  std::map<std::string, std::uint64_t> counts_;
  std::vector<Pending> pending_;
};

}  // namespace

void check_vtk_xml_structure(const fs::path& path) {
  Checker c(path);
  c.run(path);
}

}  // namespace gs
