#include "csv_reader.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "craneassist/files/text_file.hpp"
#include "text_fields.hpp"

namespace craneassist::input::detail {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

// Walks the lines of a file's text: 1-based numbers, '\r' of a CRLF ending removed, a leading
// byte-order mark skipped.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {
    if (text_.starts_with(kUtf8Bom)) text_.remove_prefix(kUtf8Bom.size());
  }

  // The next line (raw: untrimmed), false at the end of the text.
  bool next(std::string_view& raw) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    raw = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++number_;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    return true;
  }
  std::size_t number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

bool is_comment_or_blank(std::string_view content) {
  return content.empty() || content.front() == '#';
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

class Reader {
 public:
  Reader(std::string_view source, const CsvFormat& format)
      : source_(source),
        format_(format),
        min_columns_(format.columns.size() - format.optional_columns) {}

  CsvFile read(std::string_view text, const std::function<void(const CsvRow&)>& on_row);

 private:
  FileError error(std::size_t line, std::string_view field, std::string reason) const {
    return FileError(std::string(source_), line, std::string(field), std::move(reason));
  }
  void check_header(std::string_view content, std::size_t line);
  double field_value(const CsvColumn& column, std::string_view text, std::size_t line) const;

  std::string_view source_;
  const CsvFormat& format_;
  std::size_t min_columns_;
  std::size_t columns_ = 0;  // of the header read
  std::vector<std::string_view> fields_;
  std::vector<double> values_;
  double previous_time_ = 0.0;
  std::size_t previous_line_ = 0;  // 0: no data row yet
};

void Reader::check_header(std::string_view content, std::size_t line) {
  split_fields(content, fields_);
  bool ok = fields_.size() >= min_columns_ && fields_.size() <= format_.columns.size();
  for (std::size_t i = 0; ok && i < fields_.size(); ++i) ok = fields_[i] == format_.columns[i].name;
  if (!ok) {
    std::string reason = "expected the header ";
    for (std::size_t n = min_columns_; n <= format_.columns.size(); ++n) {
      if (n > min_columns_) reason += " or ";
      reason.append("'").append(csv_header(format_, n)).append("'");
    }
    throw error(line, "", reason.append(", got ").append(quoted(content)));
  }
  columns_ = fields_.size();
}

double Reader::field_value(const CsvColumn& column, std::string_view text, std::size_t line) const {
  if (column.kind == CsvKind::kFlag) {
    if (text == "0" || text == "1") return text == "1" ? 1.0 : 0.0;
    throw error(
        line, column.name,
        text.empty() ? std::string("missing value") : "expected 0 or 1, got " + quoted(text));
  }
  double value = 0.0;
  std::string reason;
  if (!parse_number(text, value, reason)) throw error(line, column.name, std::move(reason));
  if (column.kind == CsvKind::kTime) {
    if (value < 0.0) throw error(line, column.name, "negative time: " + quoted(text));
    if (value > kMaxFileTime_s) {
      throw error(line, column.name,
                  "time " + number(value) + " s is beyond the longest run a file may describe, " +
                      number(kMaxFileTime_s) + " s (24 h)");
    }
    if (previous_line_ > 0) {
      std::string problem;
      if (!(value > previous_time_)) {
        problem = "time not strictly increasing: " + number(value) + " s follows " +
                  number(previous_time_) + " s";
      } else if (value - previous_time_ < format_.min_time_step_s) {
        problem = "time step of " + number(value - previous_time_) + " s after " +
                  number(previous_time_) + " s is below the minimum of " +
                  number(format_.min_time_step_s) + " s";
      }
      if (!problem.empty()) {
        throw error(line, column.name, problem + " (line " + std::to_string(previous_line_) + ")");
      }
    }
  } else if (std::abs(value) > column.limit) {
    throw error(line, column.name,
                "magnitude of " + number(value) + " " + column.unit + " exceeds the limit of " +
                    number(column.limit) + " " + column.unit);
  }
  return value;
}

CsvFile Reader::read(std::string_view text, const std::function<void(const CsvRow&)>& on_row) {
  CsvFile file;
  Lines lines(text);
  std::string_view raw;
  while (lines.next(raw)) {
    const std::size_t line = lines.number();
    const std::string_view content = trim(raw);
    if (is_comment_or_blank(content)) {
      if (!content.empty()) {
        std::string_view comment = raw.substr(raw.find('#') + 1);
        if (comment.starts_with(' ')) comment.remove_prefix(1);
        // Carriage returns left at the end (a line ending "\r\r\n") are line-end debris, not
        // text: kept, they would be read as a CRLF ending when the comment is written back.
        while (comment.ends_with('\r')) comment.remove_suffix(1);
        file.comments.emplace_back(comment);
      }
      continue;
    }
    if (columns_ == 0) {
      check_header(content, line);
      file.header_line = line;
      continue;
    }
    split_fields(content, fields_);
    if (fields_.size() != columns_) {
      throw error(line, "",
                  "expected " + std::to_string(columns_) + " fields (" +
                      csv_header(format_, columns_) + "), got " + std::to_string(fields_.size()));
    }
    if (file.rows >= format_.max_rows) {
      throw error(line, "",
                  "too many data rows (limit " + std::to_string(format_.max_rows) + " rows)");
    }
    values_.clear();
    for (std::size_t i = 0; i < columns_; ++i) {
      values_.push_back(field_value(format_.columns[i], fields_[i], line));
    }
    on_row(CsvRow{source_, line, values_, fields_});
    for (std::size_t i = 0; i < columns_; ++i) {
      if (format_.columns[i].kind == CsvKind::kTime) previous_time_ = values_[i];
    }
    previous_line_ = line;
    ++file.rows;
  }
  // Whole-file problems are reported at the last line (line 1 for an empty file).
  file.last_line = std::max<std::size_t>(lines.number(), 1);
  if (columns_ == 0) {
    throw error(file.last_line, "",
                "missing header '" + csv_header(format_, min_columns_) +
                    "' (no line other than comments and blank lines)");
  }
  if (file.rows == 0) throw error(file.last_line, "", "no data rows after the header");
  file.columns = columns_;
  return file;
}

}  // namespace

std::string csv_header(const CsvFormat& format, std::size_t columns) {
  std::string header;
  for (std::size_t i = 0; i < std::min(columns, format.columns.size()); ++i) {
    if (i > 0) header += ',';
    header += format.columns[i].name;
  }
  return header;
}

FileError CsvRow::error(std::string_view field, std::string reason) const {
  return FileError(std::string(source), line, std::string(field), std::move(reason));
}

CsvFile read_csv(std::string_view text, std::string_view source_name, const CsvFormat& format,
                 const std::function<void(const CsvRow&)>& on_row) {
  return Reader(source_name, format).read(text, on_row);
}

std::string_view header_line(std::string_view text) {
  Lines lines(text);
  std::string_view raw;
  while (lines.next(raw)) {
    const std::string_view content = trim(raw);
    if (!is_comment_or_blank(content)) return content;
  }
  return {};
}

std::string read_file_text(const std::filesystem::path& path, std::string_view kind) {
  try {
    return files::read_text_file(path, files::kMaxCsvBytes, kind);
  } catch (const files::ReadError& e) {
    throw FileError(e.file(), 0, "", e.reason());
  }
}

}  // namespace craneassist::input::detail
