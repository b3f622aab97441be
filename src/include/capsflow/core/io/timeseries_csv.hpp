#pragma once
// timeseries.csv: one row of scalar diagnostics per output time (docs/scene-and-output.md §3.4).
//
// The header comes from the first row's names; later rows must have the same names in the same
// order (a CSV whose columns shift is worse than an error). Each row is flushed, so `tail -f` and
// pandas see it at once. Numbers use the shortest decimal form that reads back to the same
// double (fmt "{}", bit-exact like %.17g, but 0.1 prints as 0.1); NaN and infinities print as
// nan / inf, which numpy and pandas read.
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace capsflow::io {

using CsvRow = std::vector<std::pair<std::string, double>>;

class TimeseriesCsv {
 public:
  // Opens `path` for appending, creating it if needed. If it already has a header (a restarted
  // run), that header is adopted and new rows must match it.
  explicit TimeseriesCsv(std::filesystem::path path);
  ~TimeseriesCsv();
  TimeseriesCsv(TimeseriesCsv&& o) noexcept;
  TimeseriesCsv& operator=(TimeseriesCsv&& o) noexcept;
  TimeseriesCsv(const TimeseriesCsv&) = delete;
  TimeseriesCsv& operator=(const TimeseriesCsv&) = delete;

  void append_row(const CsvRow& row);
  const std::vector<std::string>& columns() const { return columns_; }
  const std::filesystem::path& path() const { return path_; }

  // Restart: keep the header and the rows whose time column ("t", else the first column) is
  // <= t_restart; drop later rows and an incomplete last line left by a crash. Rewrites the file
  // atomically. Returns the number of rows dropped. A missing file is not an error (returns 0).
  static std::size_t truncate_after(const std::filesystem::path& path, double t_restart);

  // The header line and a row's line as append_row writes them (no newline). Throws
  // std::invalid_argument for an empty row or a bad column name.
  static std::string header_line(const CsvRow& row);
  static std::string value_line(const CsvRow& row);

  // Restart: when the file has fewer data rows than `lines` (a row cut by a crash and dropped by
  // truncate_after), rewrites it atomically as `header` and `lines` (run.h5's copies, in time
  // order). Returns the number of rows restored (0: nothing was missing, the file is unchanged).
  static std::size_t restore_rows(const std::filesystem::path& path, const std::string& header,
                                  const std::vector<std::string>& lines);

 private:
  // The row's column names, checked (non-empty row, no comma, quote or line break in a name).
  static std::vector<std::string> column_names(const CsvRow& row);
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::vector<std::string> columns_;
};

}  // namespace capsflow::io
