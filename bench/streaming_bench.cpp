// Streaming analysis of a recording on disk (detect::analyze_streaming: Welch PSD + moments read
// block by block).
//
//  BM_AnalyzeStreaming: a 10^7-sample channel (Gaussian noise + a tone, written by
//    diag::write_recording with its default deflate compression to the temporary directory)
//    analysed from disk; items_per_second = samples/s including HDF5 reading and decompression.
//
// Two non-benchmark modes for bench/streaming_memory.sh (the 4 GB peak-memory check):
//  bench_streaming --write FILE --samples N [--deflate L]
//      writes a geardiag recording with one channel "accel" (25.6 kHz) of N samples, generated
//      and written 2^20 samples at a time through the HDF5 C API (diag::write_recording needs the
//      whole record in memory), chunked 65536 samples like write_recording, deflate level L
//      (default 0: a 4 GB file stays 4 GB and writing is not compression-bound).
//  bench_streaming --analyze FILE [--block N]
//      analyze_streaming of "accel"; prints samples, blocks, CPU seconds, samples/s, the
//      statistics and the PSD peak.
#include <benchmark/benchmark.h>
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "detect/analysis/streaming.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/recording.hpp"

namespace {

constexpr double kFs = 25600.0;
constexpr double kToneHz = 1234.5;

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Sample i of the test signal: a tone of amplitude 2 and unit Gaussian noise.
struct Generator {
  std::mt19937_64 rng{20240601};
  std::normal_distribution<double> g;
  std::uint64_t i = 0;
  void fill(std::vector<double>& out) {
    for (double& v : out) {
      v = 2.0 * std::sin(2 * std::numbers::pi * kToneHz * static_cast<double>(i++) / kFs) + g(rng);
    }
  }
};

bool ok(herr_t status, const char* what) {
  if (status < 0) std::cerr << "streaming writer: " << what << " failed\n";
  return status >= 0;
}

int write_big(const std::string& path, std::uint64_t samples, int deflate) {
  hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) {
    std::cerr << "streaming writer: cannot create " << path << '\n';
    return 1;
  }
  // Root attributes of the format (libdiag/include/diag/io/hdf5.hpp).
  auto string_attr = [](hid_t obj, const char* name, const char* value) {
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    const bool good = attr >= 0 && H5Awrite(attr, type, &value) >= 0;
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
    return good;
  };
  bool good = string_attr(file, "format", "geardiag-recording") &&
              string_attr(file, "creator", "bench_streaming");
  {
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t attr = H5Acreate2(file, "format_version", H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
    const int version = 1;
    good = good && attr >= 0 && ok(H5Awrite(attr, H5T_NATIVE_INT, &version), "format_version");
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
  }
  hid_t group = H5Gcreate2(file, "signals", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const hsize_t length = samples;
  const hsize_t chunk = std::min<hsize_t>(65536, length);
  hid_t space = H5Screate_simple(1, &length, nullptr);
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  good = good && ok(H5Pset_chunk(dcpl, 1, &chunk), "chunk");
  if (deflate > 0) {
    good = good && ok(H5Pset_shuffle(dcpl), "shuffle") &&
           ok(H5Pset_deflate(dcpl, static_cast<unsigned>(deflate)), "deflate");
  }
  hid_t ds = H5Dcreate2(group, "accel", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  good = good && ds >= 0;
  if (good) {
    hid_t aspace = H5Screate(H5S_SCALAR);
    hid_t attr = H5Acreate2(ds, "fs_hz", H5T_IEEE_F64LE, aspace, H5P_DEFAULT, H5P_DEFAULT);
    good = attr >= 0 && ok(H5Awrite(attr, H5T_NATIVE_DOUBLE, &kFs), "fs_hz");
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(aspace);
    good = good && string_attr(ds, "unit", "m/s^2") && string_attr(ds, "direction", "vertical") &&
           string_attr(ds, "location", "b1");
  }
  Generator gen;
  std::vector<double> block(std::size_t{1} << 20);
  for (std::uint64_t offset = 0; good && offset < samples; offset += block.size()) {
    const hsize_t n = std::min<std::uint64_t>(block.size(), samples - offset);
    block.resize(n);
    gen.fill(block);
    const hsize_t start = offset;
    hid_t fspace = H5Dget_space(ds);
    H5Sselect_hyperslab(fspace, H5S_SELECT_SET, &start, nullptr, &n, nullptr);
    hid_t mspace = H5Screate_simple(1, &n, nullptr);
    good = ok(H5Dwrite(ds, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, block.data()), "write");
    H5Sclose(mspace);
    H5Sclose(fspace);
  }
  if (ds >= 0) H5Dclose(ds);
  H5Pclose(dcpl);
  H5Sclose(space);
  if (group >= 0) H5Gclose(group);
  good = ok(H5Fclose(file), "close") && good;
  if (!good) return 1;
  std::cout << "wrote " << samples << " samples (" << samples * 8.0 / (1 << 30)
            << " GiB of float64) to " << path << '\n';
  return 0;
}

int analyze(const std::string& path, std::size_t block) {
  diag::RecordingReader reader(path);
  detect::StreamingOptions o;
  o.welch.nperseg = 4096;
  o.block_samples = block;
  const double c0 = cpu_seconds();
  const detect::StreamingSummary s = detect::analyze_streaming(reader, "accel", o);
  const double cpu = cpu_seconds() - c0;
  std::size_t peak = 1;
  for (std::size_t k = 1; k < s.psd.value.size(); ++k)
    if (s.psd.value[k] > s.psd.value[peak]) peak = k;
  std::cout << "analysed " << s.channel << ": " << s.samples << " samples in " << s.blocks
            << " blocks of " << block << ", " << cpu << " s CPU, " << s.samples / cpu / 1e6
            << " M samples/s; mean " << s.moments.mean << ", rms " << s.moments.rms()
            << ", kurtosis " << s.moments.kurtosis() << ", PSD peak at " << s.psd.frequency_hz[peak]
            << " Hz (" << s.psd.segments << " segments)\n";
  return 0;
}

void BM_AnalyzeStreaming(benchmark::State& state) {
  const std::uint64_t n = static_cast<std::uint64_t>(state.range(0));
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("geardiag_bench_streaming_" + std::to_string(::getpid()) + ".h5");
  {
    diag::Recording rec;
    diag::Signal s;
    s.name = "accel";
    s.fs_hz = kFs;
    s.unit = "m/s^2";
    s.direction = diag::Direction::kVertical;
    s.location = "b1";
    s.samples.resize(n);
    Generator gen;
    gen.fill(s.samples);
    rec.signals.push_back(std::move(s));
    diag::write_recording(path, rec);
  }
  detect::StreamingOptions o;
  o.welch.nperseg = 4096;
  for (auto _ : state) {
    diag::RecordingReader reader(path);
    const detect::StreamingSummary s = detect::analyze_streaming(reader, "accel", o);
    benchmark::DoNotOptimize(s.psd.value.data());
  }
  std::filesystem::remove(path);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_AnalyzeStreaming)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  std::string write_path, analyze_path;
  std::uint64_t samples = 0;
  std::size_t block = std::size_t{1} << 20;
  int deflate = 0;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--write") == 0) write_path = argv[i + 1];
    if (std::strcmp(argv[i], "--analyze") == 0) analyze_path = argv[i + 1];
    if (std::strcmp(argv[i], "--samples") == 0) samples = std::stoull(argv[i + 1]);
    if (std::strcmp(argv[i], "--block") == 0) block = std::stoull(argv[i + 1]);
    if (std::strcmp(argv[i], "--deflate") == 0) deflate = std::stoi(argv[i + 1]);
  }
  try {
    if (!write_path.empty()) {
      if (samples == 0) {
        std::cerr << "usage: bench_streaming --write FILE --samples N [--deflate L]\n";
        return 2;
      }
      return write_big(write_path, samples, deflate);
    }
    if (!analyze_path.empty()) return analyze(analyze_path, block);
  } catch (const std::exception& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
