#include "craneassist/control/csv_log.hpp"

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "craneassist/control/log_fields.hpp"

namespace craneassist::control {

std::string CsvLog::header(int dof, bool base) {
  return csv_header(dof, base);
}

CsvLog::CsvLog(const std::filesystem::path& path, int dof, std::size_t capacity_rows, bool base)
    : path_(path), dof_(dof), base_(base), ring_(capacity_rows) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    throw std::runtime_error(path.string() + ": cannot open the log file for writing");
  }
  std::fprintf(file_, "%s\n", header(dof, base).c_str());
  writer_ = std::thread([this] { writer_loop(); });
}

CsvLog::~CsvLog() {
  close();
}

bool CsvLog::push(const LogRow& row) noexcept {
  if (ring_.push(row)) return true;
  dropped_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void CsvLog::write_row(const LogRow& r) {
  bool first = true;
  const auto cell = [&](const Field& f, double x, std::size_t component) {
    if (!first) std::fputc(',', file_);
    first = false;
    if (f.csv_empty_if_nan && !std::isfinite(x)) return;
    // The component's format where the field lists one per component.
    const std::string_view format = list_item(f.csv_format, component);
    char one[16];
    if (format.size() >= sizeof one) return;
    std::memcpy(one, format.data(), format.size());
    one[format.size()] = '\0';
    std::fprintf(file_, one, x * f.csv_scale);
  };
  visit_fields(r, [&](const Field& f, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (f.csv == nullptr || (f.base_only && !base_)) return;
    if constexpr (std::is_same_v<T, const char*>) {
      if (!first) std::fputc(',', file_);
      first = false;
      std::fputs(value, file_);
    } else if constexpr (std::is_arithmetic_v<T>) {
      cell(f, static_cast<double>(value), 0);
    } else {
      const std::size_t n = f.per_joint ? static_cast<std::size_t>(dof_) : value.size();
      for (std::size_t k = 0; k < n; ++k) cell(f, value[k], f.per_joint ? 0 : k);
    }
  });
  std::fputc('\n', file_);
  written_.fetch_add(1, std::memory_order_relaxed);
}

void CsvLog::writer_loop() {
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    while (const LogRow* row = ring_.front()) {
      write_row(*row);
      ring_.pop();
    }
    if (stopping) return;  // everything pushed before stop_ was set has been written
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::size_t CsvLog::close() {
  if (writer_.joinable()) {
    stop_.store(true, std::memory_order_release);
    writer_.join();
  }
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  return dropped_.load();
}

}  // namespace craneassist::control
