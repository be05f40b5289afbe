// Test helper: rows of a shipped data/ CSV (comment lines and the header skipped), split on commas.
#pragma once
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace exotwin {

inline std::vector<std::vector<std::string>> ReadDataRows(const std::string& file) {
  std::ifstream in(std::string(EXOTWIN_SOURCE_DIR) + "/data/" + file);
  EXPECT_TRUE(in.good()) << file;
  std::vector<std::vector<std::string>> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

}  // namespace exotwin
