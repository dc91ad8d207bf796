#include "diag/io/import.hpp"

#include <sndfile.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/printable.hpp"
#include "diag/util/number_format.hpp"
#include "mat_file.hpp"

namespace diag {

namespace {

// Sampling rates that disagree by more than this fraction are refused (import.hpp); time stamps
// must be uniformly spaced within the same fraction of the sample period.
constexpr double kRateRelTol = 1e-3;

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string finite_error(double value) {
  return std::string(std::isnan(value) ? "NaN" : "infinite") + " value; samples must be finite";
}

void check_option_fs(const std::string& where, const ImportOptions& options) {
  if (options.fs_hz && (!(*options.fs_hz > 0.0) || !std::isfinite(*options.fs_hz))) {
    throw InputError(format_error(
        where, "fs_hz", format_shortest(*options.fs_hz) + " Hz is not a finite rate > 0"));
  }
}

std::string count_text(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

bool rates_agree(double a, double b) { return std::abs(a - b) <= kRateRelTol * std::abs(b); }

// ---- CSV -----------------------------------------------------------------------------------

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

Recording import_csv(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options) {
  LineReader reader(path.string(), where, ends_with(lower(path.filename().string()), ".gz"));
  std::string line;
  bool have_line = false;
  while ((have_line = reader.next(line)) && blank(line)) {
  }
  if (!have_line) throw InputError(format_error(where, "", "empty file (no header row)"));
  if (line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 BOM

  const char delimiter = line.find(',') != std::string::npos    ? ','
                         : line.find('\t') != std::string::npos ? '\t'
                         : line.find(';') != std::string::npos  ? ';'
                                                                : ',';
  std::vector<std::string_view> fields;
  split(line, delimiter, fields);
  const std::size_t n_columns = fields.size();

  // A first row made only of numbers is data: the columns are then named ch0, ch1, ...
  bool has_header = false;
  for (const auto& f : fields) {
    double ignored = 0;
    if (!parse_number(f, ignored)) has_header = true;
  }
  std::vector<std::string> names(n_columns);
  int time_column = -1;
  std::set<std::string> seen;
  for (std::size_t c = 0; c < n_columns; ++c) {
    names[c] = has_header && !fields[c].empty() ? std::string(fields[c]) : "ch" + std::to_string(c);
    std::replace(names[c].begin(), names[c].end(), '/', '_');  // '/' separates HDF5 paths
    if (!seen.insert(names[c]).second) {
      throw InputError(format_error(where, "line " + std::to_string(reader.line_number()),
                                    "column name '" + names[c] + "' appears twice"));
    }
    if (has_header && time_column < 0 && is_time_column(names[c]))
      time_column = static_cast<int>(c);
  }

  check_option_fs(where, options);
  if (time_column < 0 && !options.fs_hz) {  // refuse before reading a long file
    throw InputError(format_error(where, "fs_hz",
                                  "no time column (time, t, time_s or time_sec) and no sampling "
                                  "rate given (--fs)"));
  }

  std::vector<std::vector<double>> columns(n_columns);
  // The finest printed step among the time stamps [s]: 1e-6 for "%.6f" logs, ~1e-17 for
  // shortest round-trip text.
  double time_resolution = std::numeric_limits<double>::infinity();
  auto parse_row = [&](std::size_t line_number) {
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
               names[c] + "')";
      };
      if (!parse_number(fields[c], value)) {
        throw InputError(format_error(where, field_name(),
                                      fields[c].empty()
                                          ? std::string("empty field")
                                          : "'" + std::string(fields[c]) + "' is not a number"));
      }
      if (!std::isfinite(value))
        throw InputError(format_error(where, field_name(), finite_error(value)));
      if (static_cast<int>(c) == time_column) {
        time_resolution = std::min(time_resolution, print_resolution(fields[c]));
      }
      columns[c].push_back(value);
    }
  };
  if (!has_header) parse_row(reader.line_number());
  while (reader.next(line)) {
    if (blank(line)) continue;
    split(line, delimiter, fields);
    parse_row(reader.line_number());
  }
  const std::size_t n_rows = columns.empty() ? 0 : columns[0].size();
  if (n_rows == 0) throw InputError(format_error(where, "", "no data rows after the header"));

  double fs_hz = options.fs_hz.value_or(0.0);
  if (time_column >= 0) {
    const std::vector<double>& t = columns[time_column];
    const std::string field = "column '" + names[time_column] + "'";
    if (n_rows < 2) {
      throw InputError(format_error(where, field, "one time stamp cannot give a sampling rate"));
    }
    const double dt = (t.back() - t.front()) / static_cast<double>(n_rows - 1);
    if (!(dt > 0)) {
      throw InputError(format_error(where, field, "time stamps must increase"));
    }
    // Allowed step error: 0.1 % of the period, plus the rounding of fixed-point time stamps
    // (two half units of the last digit; only when that is below a tenth of the period, since
    // coarser stamps cannot show uniformity), plus the round-off of subtracting large times.
    const double rounding = time_resolution <= 0.1 * dt ? 1.5 * time_resolution : 0.0;
    const double scale = std::max(std::abs(t.front()), std::abs(t.back()));
    const double tolerance = kRateRelTol * dt + rounding + 8e-16 * scale;
    for (std::size_t i = 1; i < n_rows; ++i) {
      const double step = t[i] - t[i - 1];
      if (std::abs(step - dt) > tolerance) {
        throw InputError(format_error(where, field,
                                      "time stamps are not uniformly spaced within 0.1 %: step " +
                                          format_shortest(step) + " s between rows " +
                                          std::to_string(i) + " and " + std::to_string(i + 1) +
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
    if (!options.fs_hz) fs_hz = fs_time_hz;
  }

  Recording rec;
  for (std::size_t c = 0; c < n_columns; ++c) {
    if (static_cast<int>(c) == time_column) continue;
    Signal s;
    s.name = names[c];
    s.fs_hz = fs_hz;
    s.samples = std::move(columns[c]);
    rec.signals.push_back(std::move(s));
  }
  if (rec.signals.empty()) {
    throw InputError(format_error(where, "", "no data columns besides the time column"));
  }
  return rec;
}

// ---- libsndfile ----------------------------------------------------------------------------

std::uint32_t little_u32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

// A RIFF/WAVE file whose "data" chunk declares more bytes than the file holds is refused:
// libsndfile would read the samples present and report that many frames, taking a cut file for
// a short recording. The sizes 0 and 0xFFFFFFFF mean "unknown length" (written while streaming)
// and are left to libsndfile. Other formats are not inspected.
void check_wav_chunks(const std::filesystem::path& path, const std::string& where,
                      std::uint64_t file_size) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[12] = {};
  if (!in.read(reinterpret_cast<char*>(head), sizeof head)) return;
  if (std::memcmp(head, "RIFF", 4) != 0 || std::memcmp(head + 8, "WAVE", 4) != 0) return;
  std::uint64_t offset = 12;
  // Each chunk advances by at least 8 bytes: at most file_size / 8 iterations.
  while (offset + 8 <= file_size) {
    unsigned char chunk[8];
    in.seekg(static_cast<std::streamoff>(offset));
    if (!in.read(reinterpret_cast<char*>(chunk), sizeof chunk)) return;
    const std::uint64_t size = little_u32(chunk + 4);
    const std::uint64_t body = offset + 8;
    if (std::memcmp(chunk, "data", 4) == 0) {
      if (size != 0 && size != 0xFFFFFFFFu && body + size > file_size) {
        throw InputError(format_error(where, "data chunk",
                                      "truncated: the header declares " + std::to_string(size) +
                                          " bytes of samples, the file holds " +
                                          std::to_string(file_size - body)));
      }
      return;
    }
    offset = body + size + (size & 1);  // chunks are padded to an even length
  }
}

Recording import_sound(const std::filesystem::path& path, const std::string& where,
                       const ImportOptions& options, std::uint64_t file_size) {
  check_wav_chunks(path, where, file_size);
  SF_INFO info{};
  SNDFILE* file = sf_open(path.string().c_str(), SFM_READ, &info);
  if (file == nullptr) {
    throw InputError(format_error(where, "",
                                  std::string("unrecognised format (expected .csv, .csv.gz, .mat, "
                                              ".h5 or a sound file libsndfile reads): ") +
                                      sf_strerror(nullptr)));
  }
  const auto frames = static_cast<std::size_t>(std::max<sf_count_t>(info.frames, 0));
  const auto channels = static_cast<std::size_t>(std::max(info.channels, 0));
  // A header's frame count is believed only as far as the file could hold it: 1024 samples per
  // byte bounds even a lossless coder on silence (FLAC's constant subframes), so a corrupted
  // count cannot make this allocate without limit.
  if (channels == 0 || frames > file_size * 1024 / channels) {
    sf_close(file);
    throw InputError(format_error(where, "",
                                  "the header declares " + std::to_string(frames) + " frames of " +
                                      std::to_string(channels) + " channels, more than the " +
                                      std::to_string(file_size) + "-byte file can hold"));
  }
  std::vector<double> interleaved(frames * channels);
  const sf_count_t read = sf_readf_double(file, interleaved.data(), info.frames);
  sf_close(file);
  if (read != info.frames) {
    throw InputError(format_error(where, "",
                                  "truncated: read " + std::to_string(read) + " of " +
                                      std::to_string(info.frames) + " frames"));
  }
  if (frames == 0) throw InputError(format_error(where, "", "empty file (no samples)"));
  check_option_fs(where, options);

  Recording rec;
  for (std::size_t c = 0; c < channels; ++c) {
    Signal s;
    s.name = "ch" + std::to_string(c);
    s.fs_hz = options.fs_hz.value_or(static_cast<double>(info.samplerate));
    s.samples.resize(frames);
    for (std::size_t i = 0; i < frames; ++i) {
      const double value = interleaved[i * channels + c];
      if (!std::isfinite(value)) {
        throw InputError(format_error(where, "channel " + s.name + ", sample " + std::to_string(i),
                                      finite_error(value)));
      }
      s.samples[i] = value;
    }
    rec.signals.push_back(std::move(s));
  }
  rec.metadata["source_fs_hz"] = std::to_string(info.samplerate);
  return rec;
}

// ---- MATLAB .mat ---------------------------------------------------------------------------

// Integer classes print exactly; floating ones with the shortest round-trip text.
std::string scalar_text(const mat::Variable& v) {
  if (!v.exact_text.empty()) return v.exact_text;
  if (v.integer_class) return std::to_string(static_cast<long long>(v.values[0]));
  return format_shortest(v.values[0]);
}

// The Case Western Reserve University bearing data's naming (its "Data Files" pages): variable
// X<nnn>_DE_time is the accelerometer at the drive end, X<nnn>_FE_time at the fan end,
// X<nnn>_BA_time on the base. Those channels get that location ("drive_end", "fan_end", "base"),
// so a description whose bearing carries the name finds its sensor (channels.hpp); the unit is
// left unknown (the files do not give it). One note lists them.
void cwru_locations(Recording& rec) {
  static const std::pair<const char*, const char*> kSites[] = {
      {"_DE_time", "drive_end"}, {"_FE_time", "fan_end"}, {"_BA_time", "base"}};
  std::string named;
  for (Signal& s : rec.signals) {
    const std::string& n = s.name;
    std::size_t digits = 0;
    while (1 + digits < n.size() && std::isdigit(static_cast<unsigned char>(n[1 + digits])))
      ++digits;
    if (n.size() != 1 + digits + 8 || n[0] != 'X' || digits == 0 || !s.location.empty()) continue;
    for (const auto& [suffix, site] : kSites) {
      if (n.compare(1 + digits, 8, suffix) != 0) continue;
      s.location = site;
      named += (named.empty() ? "" : ", ") + n + " at " + site;
    }
  }
  if (!named.empty()) {
    rec.notes.push_back("sensor locations from the CWRU bearing data's variable names: " + named);
  }
}

Recording import_mat(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options, std::uint64_t file_size) {
  // Level 7.3 is HDF5: read through the project's one HDF5 open and the crash guard (mat73.cpp).
  std::vector<std::string> notes;
  std::vector<mat::Variable> vars =
      mat::is_mat73(path) ? mat::read_mat73_variables(path, &notes)
                          : mat::read_numeric_variables(path, where, file_size, &notes);
  Recording rec;
  rec.notes = std::move(notes);
  std::vector<std::pair<std::string, double>> rpm_values;
  for (mat::Variable& var : vars) {
    if (var.dims.size() != 2) continue;
    if (var.dims[0] != 1 && var.dims[1] != 1) continue;  // matrices are not channels
    if (var.values.empty()) continue;
    if (var.values.size() == 1) {
      rec.metadata[var.name] = scalar_text(var);
      const std::string lname = lower(var.name);
      // A speed stored with the data (CWRU: X097RPM, X105RPM, ...): the input shaft's speed.
      if (ends_with(lname, "rpm") && var.values[0] > 0 && var.values[0] < 1e6) {
        rpm_values.emplace_back(var.name, var.values[0]);
      }
      continue;
    }
    for (std::size_t i = 0; i < var.values.size(); ++i) {
      if (!std::isfinite(var.values[i])) {
        throw InputError(format_error(where,
                                      "variable " + var.name + ", sample " + std::to_string(i),
                                      finite_error(var.values[i])));
      }
    }
    Signal s;
    s.name = var.name;
    s.samples = std::move(var.values);
    rec.signals.push_back(std::move(s));
  }
  if (rec.signals.empty()) {
    throw InputError(format_error(where, "", "no numeric vector variables (channels) found"));
  }
  check_option_fs(where, options);
  if (!options.fs_hz) {
    throw InputError(
        format_error(where, "fs_hz", ".mat files do not store the sampling rate: give it (--fs)"));
  }
  for (Signal& s : rec.signals) s.fs_hz = *options.fs_hz;
  cwru_locations(rec);
  if (!rpm_values.empty()) {
    const auto [lo, hi] =
        std::minmax_element(rpm_values.begin(), rpm_values.end(),
                            [](const auto& a, const auto& b) { return a.second < b.second; });
    if (hi->second <= lo->second * 1.001) {
      rec.speed_rpm = rpm_values.front().second;
      rec.notes.push_back("speed " + format_shortest(rec.speed_rpm) + " rpm from variable " +
                          rpm_values.front().first);
    } else {
      rec.notes.push_back("speed variables " + lo->first + " and " + hi->first +
                          " disagree: no recorded speed");
    }
  }
  return rec;
}

// ---- geardiag HDF5 -------------------------------------------------------------------------

Recording import_hdf5(const std::filesystem::path& path, const std::string& where,
                      const ImportOptions& options) {
  Recording rec = read_recording(path);
  check_option_fs(where, options);
  if (options.fs_hz) {
    for (const auto* group : {&rec.signals, &rec.tachos}) {
      for (const Signal& s : *group) {
        if (!rates_agree(*options.fs_hz, s.fs_hz)) {
          throw InputError(format_error(where, "fs_hz",
                                        "the given " + format_shortest(*options.fs_hz) +
                                            " Hz disagrees with channel " + s.name + "'s " +
                                            format_shortest(s.fs_hz) + " Hz by more than 0.1 %"));
        }
      }
    }
  }
  return rec;
}

}  // namespace

Recording import_recording(const std::filesystem::path& path, const ImportOptions& options) {
  const std::string where = path.string();
  // A FIFO, a device (/dev/zero, also through a link), a directory: refused before any reader
  // opens them, so that none can wait or read without end.
  const std::uint64_t file_size = check_input_file(path);
  const std::string name = lower(path.filename().string());

  Recording rec;
  try {
    if (ends_with(name, ".mat")) {
      rec = import_mat(path, where, options, file_size);
    } else if (is_hdf5_file(path)) {
      rec = import_hdf5(path, where, options);
    } else if (ends_with(name, ".csv") || ends_with(name, ".csv.gz") || ends_with(name, ".tsv") ||
               ends_with(name, ".tsv.gz") || ends_with(name, ".txt") ||
               ends_with(name, ".txt.gz")) {
      rec = import_csv(path, where, options);
    } else if (ends_with(name, ".h5") || ends_with(name, ".hdf5")) {
      throw InputError(format_error(where, "", "not an HDF5 file (or truncated)"));
    } else {
      rec = import_sound(path, where, options, file_size);
    }
  } catch (const std::bad_alloc&) {
    // What a file declares was checked against its bytes; a file that is all data can still be
    // larger than this machine's memory.
    throw InputError(format_error(where, "",
                                  std::to_string(file_size) +
                                      " bytes whose samples do not fit in memory; cut the file "
                                      "or use a machine with more memory"));
  }
  rec.metadata.try_emplace("source", path.filename().string());
  // Names, units and sources come from the file: no escape sequence reaches a terminal.
  make_printable(rec);
  if (!is_hdf5_file(path)) {
    // Measured files say nothing of what their columns are: vibration until a channel map,
    // --tacho or tacho inference (channels.hpp) says otherwise.
    rec.roles_stated = false;
  }
  return rec;
}

}  // namespace diag
