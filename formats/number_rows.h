// Rows of numbers as exotwin writes them into text tables (measured-data CSV, OpenSim storage).
#pragma once
#include <string>
#include <vector>

namespace exotwin {

// Appends one line per row of `columns` (every column as long as the first) to `out`: the values
// as AppendNumber (formats/csv_table.h: the shortest text that reads back to the same double), separated by `sep`, each line ended by '\n'.
void AppendNumberRows(std::string& out, const std::vector<const std::vector<double>*>& columns, char sep);

}  // namespace exotwin
