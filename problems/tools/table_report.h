// Reports of a `diffpd table` result (table.h): a plain-text table, a
// Markdown document and a PNG chart. Computing is in table.h; these only
// format a TableResult.
#pragma once

#include <cstdio>
#include <string>

#include "tools/table.h"

namespace diffpd::problems {

// One line per row and method: seconds per evaluation forward and backward,
// evaluations, loss, speed-up, each beside the paper's value (pd-lbfgs beside
// the paper's DiffPD), then the rows' notes.
void PrintTable(const TableResult& result, std::FILE* out);

// The same as a Markdown document: a header with the date, commit, machine,
// threads and the command that measured the result (`command` for a result
// that does not store one; `command` too when it differs: the report's), the
// resumed runs, the table, the model differences (shared ones once,
// then per row).
std::string TableMarkdown(const TableResult& result, const std::string& command);

// A PNG bar chart with gnuplot: forward + backward seconds per evaluation per
// row (log scale), this library's methods beside the paper's. Throws
// std::runtime_error when gnuplot is missing or fails or nothing was measured,
// InvalidInputError for a path gnuplot cannot quote.
void WriteTablePlot(const TableResult& result, const std::string& png_path);

}  // namespace diffpd::problems
