// Strict, bounded parsing of text inputs (CSV, LIGGGHTS dumps, legacy VTK). Every failure names
// the file, the line and the offending token.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace gs::text {

/// Whole file as text. Throws InputError for a missing file, a directory, a file over
/// `max_bytes`, or binary content (NUL bytes). A leading UTF-8 byte-order mark is dropped.
std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes = 1ull << 32);
/// The whole file as bytes (binary allowed), with read_text_file's checks and messages.
std::string read_file_bytes(const std::filesystem::path& path, std::size_t max_bytes = 1ull << 32);

/// Lines without their terminators ("\r\n" or "\n").
std::vector<std::string_view> split_lines(std::string_view text);

/// Whitespace-separated tokens.
std::vector<std::string_view> split_ws(std::string_view line);

/// Comma-separated fields, each trimmed of surrounding blanks.
std::vector<std::string_view> split_csv(std::string_view line);

std::string_view trim(std::string_view s);

/// Index of each of `names` among the header fields (exact match; the last one if repeated),
/// header.size() where a name is absent.
std::vector<std::size_t> column_indices(const std::vector<std::string_view>& header,
                                        const std::vector<std::string_view>& names);

/// Parses a whole token as a double (finite or not: callers check). Throws InputError
/// "FILE: line N: bad number in FIELD (token)".
double to_double(std::string_view tok, const std::string& file, std::size_t line,
                 const std::string& field);
std::int64_t to_int(std::string_view tok, const std::string& file, std::size_t line,
                    const std::string& field);

}  // namespace gs::text
