#include "csv_table.hpp"

#include <array>
#include <charconv>
#include <cmath>

#include "text_fields.hpp"

namespace craneassist::input::detail {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

using detail::quoted;
using detail::trim;

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
      double value = 0.0;
      std::string reason;
      if (!detail::parse_number(f, value, reason)) throw error(line, columns[i], std::move(reason));
      if (i == 0 && value < 0.0) throw error(line, columns[i], "negative time: " + quoted(f));
      if (i == 0 && table.rows() > 0 && !(value > table.at(table.rows() - 1, 0))) {
        throw error(line, columns[i],
                    "time not strictly increasing: " + number(value) + " s follows " +
                        number(table.at(table.rows() - 1, 0)) + " s (line " +
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
