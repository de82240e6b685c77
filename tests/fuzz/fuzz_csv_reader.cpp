// The shared strict CSV reader of the input file formats (input/src/csv_reader.hpp): any bytes
// in one of several formats (the first byte picks it: flags, optional columns, a minimum time
// step, a row limit). The reader returns rows that keep every rule of the format, or throws
// FileError; nothing else.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "csv_reader.hpp"
#include "fuzz_check.hpp"

namespace detail = craneassist::input::detail;

namespace {

detail::CsvFormat format_for(std::uint8_t selector) {
  detail::CsvFormat format;
  format.columns = {{"t", detail::CsvKind::kTime},
                    {"a", detail::CsvKind::kNumber, (selector & 1) != 0 ? 5.0 : INFINITY, "m/s"},
                    {"b", detail::CsvKind::kNumber},
                    {"f", detail::CsvKind::kFlag}};
  format.optional_columns = (selector >> 1) % 4;  // 0..3 of the last columns
  format.max_rows = (selector & 8) != 0 ? 3 : 1000;
  format.min_time_step_s = (selector & 16) != 0 ? 1e-3 : 0.0;
  return format;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const detail::CsvFormat format = format_for(data[0]);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  (void)detail::header_line(text);
  std::size_t rows = 0;
  double previous_t = -1.0;
  try {
    const detail::CsvFile file =
        detail::read_csv(text, "fuzz.csv", format, [&](const detail::CsvRow& row) {
          FUZZ_CHECK(row.values.size() == row.text.size(), "one value per field");
          FUZZ_CHECK(row.values.size() >= format.columns.size() - format.optional_columns &&
                         row.values.size() <= format.columns.size(),
                     "a row has the header's column count");
          for (std::size_t i = 0; i < row.values.size(); ++i) {
            const double v = row.values[i];
            FUZZ_CHECK(std::isfinite(v), "every value is finite");
            switch (format.columns[i].kind) {
              case detail::CsvKind::kTime:
                FUZZ_CHECK(v >= 0.0 && v > previous_t, "time >= 0, strictly increasing");
                FUZZ_CHECK(rows == 0 || v - previous_t >= format.min_time_step_s, "time step kept");
                previous_t = v;
                break;
              case detail::CsvKind::kNumber:
                FUZZ_CHECK(std::abs(v) <= format.columns[i].limit, "within the column's limit");
                break;
              case detail::CsvKind::kFlag:
                FUZZ_CHECK(v == 0.0 || v == 1.0, "a flag is 0 or 1");
                break;
            }
          }
          ++rows;
        });
    FUZZ_CHECK(file.rows == rows && rows >= 1 && rows <= format.max_rows, "row count");
  } catch (const craneassist::input::FileError& e) {
    FUZZ_CHECK(e.file() == "fuzz.csv", "the error names the file");
    FUZZ_CHECK(std::string_view(e.what()).starts_with("fuzz.csv:"), "message FILE:LINE: ...");
  }
  return 0;
}
