// timeseries.csv writer (see timeseries_csv.hpp).
#include "capsflow/core/io/timeseries_csv.hpp"

#include <cmath>
#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/io/io_error.hpp"
#include "posix_error.hpp"

namespace capsflow::io {
namespace fs = std::filesystem;

namespace {

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + v[i];
  return s;
}

// The file split into complete lines (an unterminated last line is a crash remnant: dropped).
std::vector<std::string> complete_lines(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) detail::throw_errno("cannot read", path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1) {
    lines.push_back(text.substr(start, nl - start));
  }
  return lines;
}

}  // namespace

TimeseriesCsv::TimeseriesCsv(fs::path path) : path_(std::move(path)) {
  std::error_code ec;
  if (fs::exists(path_, ec) && fs::file_size(path_, ec) > 0) {
    const std::vector<std::string> lines = complete_lines(path_);
    if (!lines.empty()) columns_ = split_csv_line(lines.front());
    // Cut an incomplete last line (a crash mid-write), or the next row would be glued to it.
    std::uintmax_t complete = 0;
    for (const std::string& l : lines) complete += l.size() + 1;
    if (complete != fs::file_size(path_, ec)) {
      fs::resize_file(path_, complete, ec);
      if (ec) throw IoError("cannot repair '" + path_.string() + "': " + ec.message());
    }
  }
  file_ = std::fopen(path_.c_str(), "a");
  if (file_ == nullptr) detail::throw_errno("cannot open", path_);
}

TimeseriesCsv::~TimeseriesCsv() {
  if (file_ != nullptr) std::fclose(file_);
}

TimeseriesCsv::TimeseriesCsv(TimeseriesCsv&& o) noexcept
    : path_(std::move(o.path_)), file_(o.file_), columns_(std::move(o.columns_)) {
  o.file_ = nullptr;
}

TimeseriesCsv& TimeseriesCsv::operator=(TimeseriesCsv&& o) noexcept {
  if (this != &o) {
    if (file_ != nullptr) std::fclose(file_);
    path_ = std::move(o.path_);
    file_ = o.file_;
    columns_ = std::move(o.columns_);
    o.file_ = nullptr;
  }
  return *this;
}

std::vector<std::string> TimeseriesCsv::column_names(const CsvRow& row) {
  if (row.empty()) throw std::invalid_argument("empty time-series row");
  std::vector<std::string> names;
  for (const auto& [name, value] : row) {
    if (name.empty() || name.find_first_of(",\"\n\r") != std::string::npos) {
      throw std::invalid_argument("bad time-series column name '" + name + "'");
    }
    names.push_back(name);
  }
  return names;
}

std::string TimeseriesCsv::header_line(const CsvRow& row) { return join(column_names(row)); }

std::string TimeseriesCsv::value_line(const CsvRow& row) {
  std::string text;
  for (std::size_t i = 0; i < row.size(); ++i) {
    // A value not defined yet (the steady-state measure before one window) is an empty field,
    // never "nan": readers see a missing value, and "nan" in a file always means a bug.
    const double v = row[i].second;
    text += i ? "," : "";
    if (std::isfinite(v)) text += fmt::format("{}", v);
  }
  return text;
}

void TimeseriesCsv::append_row(const CsvRow& row) {
  std::vector<std::string> names;
  try {
    names = column_names(row);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path_.string() + ": " + e.what());
  }
  std::string text;
  if (columns_.empty()) {
    columns_ = names;
    text += join(names) + "\n";
  } else if (names != columns_) {
    throw std::invalid_argument(path_.string() + ": row columns (" + join(names) +
                                ") differ from the header (" + join(columns_) + ")");
  }
  text += value_line(row) + "\n";
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fflush(file_) != 0) {
    detail::throw_errno("cannot write", path_);
  }
}

std::size_t TimeseriesCsv::restore_rows(const fs::path& path, const std::string& header,
                                        const std::vector<std::string>& lines) {
  std::error_code ec;
  const std::size_t have = fs::exists(path, ec) ? complete_lines(path).size() : 0;
  const std::size_t rows = have > 0 ? have - 1 : 0;
  if (lines.empty() || rows >= lines.size()) return 0;
  std::string text = header + "\n";
  for (const std::string& l : lines) text += l + "\n";
  write_file_atomically(path, text);
  return lines.size() - rows;
}

std::size_t TimeseriesCsv::truncate_after(const fs::path& path, double t_restart) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return 0;
  const std::vector<std::string> lines = complete_lines(path);
  if (lines.empty()) {
    write_file_atomically(path, "");
    return 0;
  }
  const std::vector<std::string> header = split_csv_line(lines.front());
  std::size_t tcol = 0;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == "t") tcol = i;
  }
  std::string kept = lines.front() + "\n";
  std::size_t dropped = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> cells = split_csv_line(lines[i]);
    bool keep = cells.size() == header.size();
    if (keep) {
      char* end = nullptr;
      errno = 0;
      const double t = std::strtod(cells[tcol].c_str(), &end);
      keep = end != cells[tcol].c_str() && *end == '\0' && t <= t_restart;
    }
    if (keep) {
      kept += lines[i] + "\n";
    } else {
      ++dropped;
    }
  }
  write_file_atomically(path, kept);
  return dropped;
}

}  // namespace capsflow::io
