// CSV and TSV files, whole or frame by frame (csv.hpp).
#include "csv.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/printable.hpp"
#include "diag/util/number_format.hpp"
#include "import_common.hpp"

namespace diag {

namespace {

using namespace import_detail;

// Reads lines from a plain or gzip-compressed file (zlib reads both). Bytes are taken as they
// are (a line may hold any byte but NUL, which no text file has: it is refused, never taken as
// the end of a line); a line longer than kMaxLineBytes, a file named .gz that is not gzip data, and
// a corrupt or truncated gzip stream are refused naming the line.
class LineReader {
 public:
  static constexpr std::size_t kMaxLineBytes = std::size_t{1} << 24;

  LineReader(const std::string& path, const std::string& where, bool gzip_name)
      : where_(where), gzip_name_(gzip_name) {
    file_ = gzopen(path.c_str(), "rb");
    if (file_ == nullptr) {
      throw InputError(
          format_error(where, "", std::string("cannot open: ") + std::strerror(errno)));
    }
    gzbuffer(file_, 1 << 18);
    buffer_.resize(1 << 18);
  }
  ~LineReader() { gzclose_r(file_); }
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  // Next line without its end-of-line characters; false at the end of the file.
  bool next(std::string& line) {
    line.clear();
    bool any = false;
    while (true) {
      if (pos_ == end_ && !fill()) break;
      any = true;
      const char* begin = buffer_.data() + pos_;
      const auto* nl = static_cast<const char*>(std::memchr(begin, '\n', end_ - pos_));
      const std::size_t n = nl != nullptr ? static_cast<std::size_t>(nl - begin) : end_ - pos_;
      if (std::memchr(begin, '\0', n) != nullptr) {
        throw InputError(format_error(where_, "line " + std::to_string(line_number_ + 1),
                                      "contains a NUL byte: binary data, not text"));
      }
      if (line.size() + n > kMaxLineBytes) {
        throw InputError(
            format_error(where_, "line " + std::to_string(line_number_ + 1),
                         "longer than " + std::to_string(kMaxLineBytes) + " bytes: not a CSV row"));
      }
      line.append(begin, n);
      pos_ += n;
      if (nl != nullptr) {
        ++pos_;
        break;
      }
    }
    if (!any) return false;
    ++line_number_;
    while (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }
  std::size_t line_number() const { return line_number_; }

 private:
  // Refills the buffer; false at the end of the data. Throws on a zlib error.
  bool fill() {
    if (eof_) return false;
    const int n = gzread(file_, buffer_.data(), static_cast<unsigned>(buffer_.size()));
    int code = Z_OK;
    const char* message = gzerror(file_, &code);
    if (n < 0 || (code != Z_OK && code != Z_STREAM_END)) {
      throw InputError(format_error(
          where_, line_number_ == 0 ? std::string() : "after line " + std::to_string(line_number_),
          std::string("corrupt or truncated gzip data: ") + message));
    }
    if (!checked_gzip_ && n > 0) {
      checked_gzip_ = true;
      if (gzip_name_ && gzdirect(file_) != 0) {
        throw InputError(format_error(where_, "", "named .gz but not gzip-compressed data"));
      }
    }
    pos_ = 0;
    end_ = static_cast<std::size_t>(n);
    if (n == 0) eof_ = true;
    return n > 0;
  }

  std::string where_;
  bool gzip_name_;
  gzFile file_ = nullptr;
  std::vector<char> buffer_;
  std::size_t pos_ = 0, end_ = 0;
  bool eof_ = false, checked_gzip_ = false;
  std::size_t line_number_ = 0;
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

bool blank(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c == ' ' || c == '\t'; });
}

void split(std::string_view line, char delimiter, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(delimiter, start);
    if (end == std::string_view::npos) {
      fields.push_back(trim(line.substr(start)));
      return;
    }
    fields.push_back(trim(line.substr(start, end - start)));
    start = end + 1;
  }
}

// Parses a whole field as a number (a leading '+' allowed). NaN and infinities parse.
bool parse_number(std::string_view field, double& value) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  if (field.empty()) return false;
  const auto result = std::from_chars(field.data(), field.data() + field.size(), value);
  return result.ec == std::errc() && result.ptr == field.data() + field.size();
}

// The rounding step of a printed number: "0.000021" -> 1e-6, "2.0833e-05" -> 1e-9.
double print_resolution(std::string_view field) {
  const std::size_t e = field.find_first_of("eE");
  const std::string_view mantissa = field.substr(0, e);
  int exponent = 0;
  if (e != std::string_view::npos) {
    std::string_view exp_text = field.substr(e + 1);
    if (!exp_text.empty() && exp_text.front() == '+') exp_text.remove_prefix(1);
    std::from_chars(exp_text.data(), exp_text.data() + exp_text.size(), exponent);
  }
  const std::size_t dot = mantissa.find('.');
  const int decimals =
      dot == std::string_view::npos ? 0 : static_cast<int>(mantissa.size() - dot - 1);
  return std::pow(10.0, exponent - decimals);
}

bool is_time_column(std::string_view name) {
  const std::string n = lower(name);
  return n == "time" || n == "t" || n == "time_s" || n == "time_sec";
}

// The header row (or its absence), the delimiter and the columns.
struct CsvHeader {
  char delimiter = ',';
  std::vector<std::string> names;
  int time_column = -1;
  bool has_header = false;
  std::size_t header_line = 0;  // the line number of the first non-blank line
};

// Reads up to the first non-blank line: the header, or (a first row made only of numbers) the
// first data row, left in `fields` / `line` for the caller to parse.
CsvHeader read_header(LineReader& reader, const std::string& where, const ImportOptions& options,
                      std::string& line, std::vector<std::string_view>& fields) {
  bool have_line = false;
  while ((have_line = reader.next(line)) && blank(line)) {
  }
  if (!have_line) throw InputError(format_error(where, "", "empty file (no header row)"));
  if (line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 BOM
  CsvHeader h;
  h.header_line = reader.line_number();
  h.delimiter = line.find(',') != std::string::npos    ? ','
                : line.find('\t') != std::string::npos ? '\t'
                : line.find(';') != std::string::npos  ? ';'
                                                       : ',';
  split(line, h.delimiter, fields);
  const std::size_t n_columns = fields.size();
  for (const auto& f : fields) {
    double ignored = 0;
    if (!parse_number(f, ignored)) h.has_header = true;
  }
  h.names.resize(n_columns);
  std::set<std::string> seen;
  for (std::size_t c = 0; c < n_columns; ++c) {
    h.names[c] =
        h.has_header && !fields[c].empty() ? std::string(fields[c]) : "ch" + std::to_string(c);
    std::replace(h.names[c].begin(), h.names[c].end(), '/', '_');  // '/' separates HDF5 paths
    if (!seen.insert(h.names[c]).second) {
      throw InputError(format_error(where, "line " + std::to_string(reader.line_number()),
                                    "column name '" + h.names[c] + "' appears twice"));
    }
    if (h.has_header && h.time_column < 0 && is_time_column(h.names[c])) {
      h.time_column = static_cast<int>(c);
    }
  }
  check_option_fs(where, options);
  if (h.time_column < 0 && !options.fs_hz) {  // refuse before reading a long file
    throw InputError(format_error(where, "fs_hz",
                                  "no time column (time, t, time_s or time_sec) and no sampling "
                                  "rate given (--fs)"));
  }
  return h;
}

// One row's fields as numbers into `columns`; `finite`: NaN and infinities refused.
void parse_row(const std::vector<std::string_view>& fields, const CsvHeader& h,
               std::size_t line_number, const std::string& where, bool finite,
               std::vector<std::vector<double>>& columns, double* time_resolution) {
  const std::size_t n_columns = h.names.size();
  if (fields.size() != n_columns) {
    throw InputError(format_error(where, "line " + std::to_string(line_number),
                                  "has " + count_text(fields.size(), "field") +
                                      ", the header has " + count_text(n_columns, "column") +
                                      " (ragged rows)"));
  }
  for (std::size_t c = 0; c < n_columns; ++c) {
    double value = 0;
    // Built only for a message: once per value it was most of the time of a large import.
    const auto field_name = [&] {
      return "line " + std::to_string(line_number) + ", column " + std::to_string(c + 1) + " ('" +
             h.names[c] + "')";
    };
    if (!parse_number(fields[c], value)) {
      throw InputError(format_error(where, field_name(),
                                    fields[c].empty()
                                        ? std::string("empty field")
                                        : "'" + std::string(fields[c]) + "' is not a number"));
    }
    if ((finite || static_cast<int>(c) == h.time_column) && !std::isfinite(value)) {
      throw InputError(format_error(where, field_name(), finite_error(value)));
    }
    if (static_cast<int>(c) == h.time_column && time_resolution != nullptr) {
      *time_resolution = std::min(*time_resolution, print_resolution(fields[c]));
    }
    columns[c].push_back(value);
  }
}

// The sampling rate from the time stamps: their mean step, every step within the tolerance of
// it (0.1 % of the period, plus the rounding of fixed-point time stamps: two half units of the
// last digit, only when that is below a tenth of the period, since coarser stamps cannot show
// uniformity; plus the round-off of subtracting large times). `first`, `last`: the first and
// last stamps; `min_step`, `max_step` and the rows where they are (1-based, the later row).
double rate_from_time(const std::string& where, const std::string& field, std::size_t n_rows,
                      double first, double last, double min_step, std::size_t min_row,
                      double max_step, std::size_t max_row, double time_resolution,
                      const ImportOptions& options) {
  if (n_rows < 2) {
    throw InputError(format_error(where, field, "one time stamp cannot give a sampling rate"));
  }
  const double dt = (last - first) / static_cast<double>(n_rows - 1);
  if (!(dt > 0)) throw InputError(format_error(where, field, "time stamps must increase"));
  const double rounding = time_resolution <= 0.1 * dt ? 1.5 * time_resolution : 0.0;
  const double scale = std::max(std::abs(first), std::abs(last));
  const double tolerance = kRateRelTol * dt + rounding + 8e-16 * scale;
  for (const auto& [step, row] : {std::pair{min_step, min_row}, std::pair{max_step, max_row}}) {
    if (std::abs(step - dt) > tolerance) {
      throw InputError(format_error(where, field,
                                    "time stamps are not uniformly spaced within 0.1 %: step " +
                                        format_shortest(step) + " s between rows " +
                                        std::to_string(row - 1) + " and " + std::to_string(row) +
                                        " of the data, mean step " + format_shortest(dt) + " s"));
    }
  }
  const double fs_time_hz = 1.0 / dt;
  if (options.fs_hz && !rates_agree(*options.fs_hz, fs_time_hz)) {
    throw InputError(format_error(where, "fs_hz",
                                  "the given " + format_shortest(*options.fs_hz) +
                                      " Hz disagrees with the time column's " +
                                      format_shortest(fs_time_hz) + " Hz by more than 0.1 %"));
  }
  return options.fs_hz.value_or(fs_time_hz);
}

// Steps between consecutive time stamps: the smallest and largest, and where.
struct StepRange {
  double first = 0, last = 0;
  double min_step = std::numeric_limits<double>::infinity(), max_step = -min_step;
  std::size_t min_row = 0, max_row = 0, rows = 0;
  void add(double t) {
    if (rows == 0) {
      first = t;
    } else {
      const double step = t - last;
      if (step < min_step) min_step = step, min_row = rows + 1;
      if (step > max_step) max_step = step, max_row = rows + 1;
    }
    last = t;
    ++rows;
  }
};

}  // namespace

Recording import_csv(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options) {
  LineReader reader(path.string(), where, ends_with(lower(path.filename().string()), ".gz"));
  std::string line;
  std::vector<std::string_view> fields;
  const CsvHeader h = read_header(reader, where, options, line, fields);
  const std::size_t n_columns = h.names.size();
  std::vector<std::vector<double>> columns(n_columns);
  // The finest printed step among the time stamps [s]: 1e-6 for "%.6f" logs, ~1e-17 for
  // shortest round-trip text.
  double time_resolution = std::numeric_limits<double>::infinity();
  if (!h.has_header)
    parse_row(fields, h, reader.line_number(), where, true, columns, &time_resolution);
  while (reader.next(line)) {
    if (blank(line)) continue;
    split(line, h.delimiter, fields);
    parse_row(fields, h, reader.line_number(), where, true, columns, &time_resolution);
  }
  const std::size_t n_rows = columns.empty() ? 0 : columns[0].size();
  if (n_rows == 0) throw InputError(format_error(where, "", "no data rows after the header"));

  double fs_hz = options.fs_hz.value_or(0.0);
  if (h.time_column >= 0) {
    StepRange steps;
    for (double t : columns[static_cast<std::size_t>(h.time_column)]) steps.add(t);
    fs_hz =
        rate_from_time(where, "column '" + h.names[static_cast<std::size_t>(h.time_column)] + "'",
                       n_rows, steps.first, steps.last, steps.min_step, steps.min_row,
                       steps.max_step, steps.max_row, time_resolution, options);
  }

  Recording rec;
  for (std::size_t c = 0; c < n_columns; ++c) {
    if (static_cast<int>(c) == h.time_column) continue;
    Signal s;
    s.name = h.names[c];
    s.fs_hz = fs_hz;
    s.samples = std::move(columns[c]);
    rec.signals.push_back(std::move(s));
  }
  if (rec.signals.empty()) {
    throw InputError(format_error(where, "", "no data columns besides the time column"));
  }
  return rec;
}

namespace {

class CsvFrames : public FrameSource {
 public:
  CsvFrames(const std::filesystem::path& path, const ImportOptions& options)
      : path_(path),
        where_(path.string()),
        gzip_(ends_with(lower(path.filename().string()), ".gz")) {
    check_input_file(path);
    LineReader reader(path_.string(), where_, gzip_);
    std::string line;
    std::vector<std::string_view> fields;
    header_ = read_header(reader, where_, options, line, fields);
    // The first pass: the rows, and the time column's steps. A log whose clock jumps (a logger
    // paused and resumed) is read all the same: its rate is the median step's, every step off
    // it beyond the tolerance is a gap, and the frames that hold a gap are refused (frame()).
    StepRange steps;
    double time_resolution = std::numeric_limits<double>::infinity();
    std::vector<double> first_steps;  // the first kMedianSteps steps: the rate of a log with gaps
    struct Candidate {
      std::size_t row, line;
      double before, after;
    };
    std::vector<Candidate> candidates;  // steps off the first steps' median by over 0.1 %
    double median_step = 0;
    double previous_t = 0;
    bool uneven = false;  // more candidates than kMaxGaps: an uneven clock, not gaps
    const auto count = [&] {
      if (header_.time_column >= 0) {
        const auto c = static_cast<std::size_t>(header_.time_column);
        double t = 0;
        if (c >= fields.size() || !parse_number(fields[c], t) || !std::isfinite(t)) {
          // The row's own message (field count, not a number, not finite).
          std::vector<std::vector<double>> scratch(header_.names.size());
          parse_row(fields, header_, reader.line_number(), where_, false, scratch, nullptr);
        }
        time_resolution = std::min(time_resolution, print_resolution(fields[c]));
        if (rows_ > 0) {
          const double step = t - previous_t;
          if (first_steps.size() < kMedianSteps) {
            first_steps.push_back(step);
            if (first_steps.size() == kMedianSteps) median_step = median(first_steps);
          }
          const double rounding =
              time_resolution <= 0.1 * median_step ? 1.5 * time_resolution : 0.0;
          if (median_step > 0 &&
              std::abs(step - median_step) > kRateRelTol * median_step + rounding) {
            if (candidates.size() < kMaxGaps) {
              candidates.push_back({rows_, reader.line_number(), previous_t, t});
            } else {
              uneven = true;
            }
          }
        }
        previous_t = t;
        steps.add(t);
      }
      ++rows_;
    };
    if (!header_.has_header) count();
    while (reader.next(line)) {
      if (blank(line)) continue;
      if (header_.time_column >= 0) split(line, header_.delimiter, fields);
      count();
    }
    if (rows_ == 0) throw InputError(format_error(where_, "", "no data rows after the header"));
    fs_hz_ = options.fs_hz.value_or(0.0);
    if (header_.time_column >= 0) {
      const std::string field =
          "column '" + header_.names[static_cast<std::size_t>(header_.time_column)] + "'";
      try {
        fs_hz_ =
            rate_from_time(where_, field, rows_, steps.first, steps.last, steps.min_step,
                           steps.min_row, steps.max_step, steps.max_row, time_resolution, options);
      } catch (const InputError&) {
        // Not uniform as a whole: gaps in a log whose steps are otherwise uniform, or refused as
        // the import refuses it.
        if (first_steps.size() < kMedianSteps || uneven) throw;
        const double dt = median_step;
        const double rounding = time_resolution <= 0.1 * dt ? 1.5 * time_resolution : 0.0;
        const double scale = std::max(std::abs(steps.first), std::abs(steps.last));
        const double tolerance = kRateRelTol * dt + rounding + 8e-16 * scale;
        for (std::size_t i = 0; i < first_steps.size(); ++i) {
          if (std::abs(first_steps[i] - dt) > tolerance) throw;  // uneven from the start
        }
        for (const Candidate& c : candidates) {
          const double step = c.after - c.before;
          if (std::abs(step - dt) <= tolerance) continue;
          // A pause is a jump forward by more than a step and a half; a shorter or a backward
          // step is an uneven clock: refused as the import refuses it.
          if (!(step > 1.5 * dt)) throw;
          gaps_.push_back({c.row, c.line, c.before, c.after});
        }
        if (gaps_.empty() || !(dt > 0)) throw;
        if (options.fs_hz && !rates_agree(*options.fs_hz, 1 / dt)) throw;
        fs_hz_ = options.fs_hz.value_or(1 / dt);
        shape_.notes.push_back(
            "the time column jumps " + count_text(gaps_.size(), "time") + " (the first from " +
            format_shortest(gaps_.front().before) + " to " + format_shortest(gaps_.front().after) +
            " s, line " + std::to_string(gaps_.front().line) +
            "): times are counted in samples from the first row, and the frames holding a jump "
            "are not examined");
      }
    }
    // What every frame is, but its samples: as import_recording gives the file.
    for (std::size_t c = 0; c < header_.names.size(); ++c) {
      if (static_cast<int>(c) == header_.time_column) continue;
      Signal s;
      s.name = header_.names[c];
      s.fs_hz = fs_hz_;
      shape_.signals.push_back(std::move(s));
    }
    if (shape_.signals.empty()) {
      throw InputError(format_error(where_, "", "no data columns besides the time column"));
    }
    shape_.metadata.try_emplace("source", path.filename().string());
    make_printable(shape_);
    shape_.roles_stated = false;
  }

  std::vector<ChannelExtent> extents() const override {
    return std::vector<ChannelExtent>(shape_.signals.size(), ChannelExtent{rows_, fs_hz_});
  }

  Recording frame(double t0_s, double t1_s) const override {
    const auto row_at = [&](double t) {
      if (!std::isfinite(t)) return rows_;
      const double n = std::floor(t * fs_hz_);
      return n <= 0 ? std::size_t{0} : std::min(rows_, static_cast<std::size_t>(n));
    };
    const std::size_t r0 = row_at(t0_s), r1 = std::max(r0, row_at(t1_s));
    for (const Gap& g : gaps_) {  // the step into row g.row lies inside the frame
      if (g.row > r0 && g.row < r1) {
        throw InputError(format_error(where_, "line " + std::to_string(g.line),
                                      "the time column jumps from " + format_shortest(g.before) +
                                          " to " + format_shortest(g.after) +
                                          " s: a gap in the log"));
      }
    }
    if (!reader_ || r0 < next_row_) rewind();
    std::string line;
    std::vector<std::string_view> fields;
    std::vector<std::vector<double>> columns(header_.names.size());
    for (auto& c : columns) c.reserve(r1 - r0);
    while (next_row_ < r1) {
      if (pending_) {
        line = std::move(*pending_);
        pending_.reset();
      } else if (!reader_->next(line)) {
        throw InputError(format_error(where_, "", "fewer rows than at the first reading"));
      }
      if (blank(line)) continue;
      if (next_row_ >= r0) {
        split(line, header_.delimiter, fields);
        parse_row(fields, header_, reader_->line_number(), where_, false, columns, nullptr);
      }
      ++next_row_;
    }
    Recording out = shape_;
    std::size_t k = 0;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (static_cast<int>(c) == header_.time_column) continue;
      out.signals[k++].samples = std::move(columns[c]);
    }
    return out;
  }

 private:
  // Back to the first data row.
  void rewind() const {
    reader_ = std::make_unique<LineReader>(path_.string(), where_, gzip_);
    std::string line;
    while (reader_->line_number() < header_.header_line && reader_->next(line)) {
    }
    // Without a header the first non-blank line was data: it is the first row.
    pending_.reset();
    if (!header_.has_header) pending_ = line;
    next_row_ = 0;
  }

  static constexpr std::size_t kMedianSteps = 1024;  // steps whose median is a gappy log's rate
  static constexpr std::size_t kMaxGaps = 10000;     // more: an uneven clock, not gaps
  struct Gap {
    std::size_t row;   // the row after the jump (0-based)
    std::size_t line;  // its line in the file
    double before, after;
  };
  static double median(std::vector<double> v) {
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
  }
  std::filesystem::path path_;
  std::string where_;
  bool gzip_ = false;
  CsvHeader header_;
  std::vector<Gap> gaps_;
  std::size_t rows_ = 0;
  double fs_hz_ = 0;
  Recording shape_;
  mutable std::unique_ptr<LineReader> reader_;
  mutable std::optional<std::string> pending_;
  mutable std::size_t next_row_ = 0;
};

}  // namespace

std::shared_ptr<const FrameSource> csv_frames(const std::filesystem::path& path,
                                              const ImportOptions& options) {
  return std::make_shared<const CsvFrames>(path, options);
}

}  // namespace diag
