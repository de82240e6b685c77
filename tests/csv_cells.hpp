// The cells of one line of a CSV log (control::CsvLog: no quoting), for the tests that read logs
// back by column (test_live_loop.cpp, test_scaling_e2e.cpp).
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace craneassist::test {

// The comma-separated cells of `line`, as std::getline splits them (no cell after a final comma).
inline std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::istringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  return cells;
}

}  // namespace craneassist::test
