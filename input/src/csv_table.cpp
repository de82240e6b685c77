#include "csv_table.hpp"

#include <array>
#include <charconv>
#include <cmath>

namespace craneassist::input::detail {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// File text quoted for a message: control and non-ASCII bytes escaped, long text shortened.
std::string quoted(std::string_view s) {
  constexpr std::size_t kMaxShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      constexpr std::string_view kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    }
  }
  if (s.size() > kMaxShown) out += "...";
  out += '\'';
  return out;
}

void split_fields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  while (true) {
    const std::size_t comma = line.find(',');
    fields.push_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

}  // namespace

std::string format_number(double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return {buffer.data(), static_cast<std::size_t>(result.ptr - buffer.data())};
}

CsvTable read_csv_table(std::string_view text, std::string_view source_name,
                        const std::vector<std::string>& columns, std::size_t max_rows) {
  const std::string source(source_name);
  std::string header;
  for (const auto& c : columns) header += (header.empty() ? "" : ",") + c;
  const auto error = [&](std::size_t line, std::string_view field, std::string reason) {
    return ReplayError(source, line, std::string(field), std::move(reason));
  };

  CsvTable table;
  table.columns = columns;
  if (text.starts_with(kUtf8Bom)) text.remove_prefix(kUtf8Bom.size());
  std::vector<std::string_view> fields;
  bool have_header = false;
  std::size_t line = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view raw = text.substr(pos, end - pos);
    pos = end + 1;
    ++line;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    const std::string_view content = trim(raw);
    if (content.empty() || content.front() == '#') continue;
    split_fields(content, fields);
    if (!have_header) {
      bool ok = fields.size() == columns.size();
      for (std::size_t i = 0; ok && i < columns.size(); ++i) ok = fields[i] == columns[i];
      if (!ok)
        throw error(line, "", "expected the header '" + header + "', got " + quoted(content));
      have_header = true;
      continue;
    }
    if (fields.size() != columns.size()) {
      throw error(line, "",
                  "expected " + std::to_string(columns.size()) + " fields (" + header + "), got " +
                      std::to_string(fields.size()));
    }
    if (table.rows() >= max_rows) {
      throw error(line, "", "too many data rows (limit " + std::to_string(max_rows) + " rows)");
    }
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const std::string_view f = fields[i];
      if (f.empty()) throw error(line, columns[i], "missing value");
      double value = 0.0;
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
      if (ec == std::errc::invalid_argument || ptr != f.data() + f.size()) {
        throw error(line, columns[i], "not a number: " + quoted(f));
      }
      if (ec == std::errc::result_out_of_range || !std::isfinite(value)) {
        throw error(line, columns[i], "not a finite number: " + quoted(f));
      }
      if (i == 0 && value < 0.0) throw error(line, columns[i], "negative time: " + quoted(f));
      if (i == 0 && table.rows() > 0 && !(value > table.at(table.rows() - 1, 0))) {
        throw error(line, columns[i],
                    "time not strictly increasing: " + format_number(value) + " s follows " +
                        format_number(table.at(table.rows() - 1, 0)) + " s (line " +
                        std::to_string(table.lines.back()) + ")");
      }
      table.values.push_back(value);
    }
    table.lines.push_back(line);
  }
  const std::size_t last_line = std::max<std::size_t>(line, 1);
  if (!have_header) {
    throw error(last_line, "",
                "missing header '" + header + "' (no line other than comments and blank lines)");
  }
  if (table.rows() == 0) throw error(last_line, "", "no data rows after the header");
  return table;
}

}  // namespace craneassist::input::detail
