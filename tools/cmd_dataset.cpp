// geardiag dataset: a labelled synthetic dataset from a spec (tools/dataset_spec.hpp): one
// simulated recording per (class, draw), with its ground truth, a manifest and a class-balance
// summary; reproducible, resumable, on every core and across MPI ranks (tools/parallel.hpp).
//
// Folder layout (docs/cli/dataset.md):
//   DIR/dataset.json        the spec, its hash, the number of recordings (written first)
//   DIR/recordings/<id>.h5  one recording each, written under a temporary name and renamed, so a
//                           name that exists is a complete file
//   DIR/manifest.csv/.jsonl one row per complete recording, rebuilt from the files at the end of
//                           every run
//   DIR/summary.json        recordings per class (complete / planned), per gear and fault type
// Resuming: the same command regenerates only the missing files (recording k depends on (seed, k)
// only); leftovers of a killed run (".tmp-<pid>" files) are removed first. A folder made from a
// different spec (another hash) is refused.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <boost/program_options.hpp>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dataset_simulator.hpp"
#include "dataset_spec.hpp"
#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/util/parallel_for.hpp"
#include "output.hpp"
#include "parallel.hpp"

namespace po = boost::program_options;
namespace fs = std::filesystem;

namespace geardiag {

namespace {

using nlohmann::json;

// HDF5 writes go one at a time (the library serialises them anyway; this keeps the temporary-file
// bookkeeping of write_output_file_via out of any doubt).
std::mutex hdf5_mutex;
// Seconds spent simulating and writing (summed over threads), for the closing line: writing is
// serialised within a process, so its share bounds the speed-up of threads (not of ranks).
std::atomic<long> simulate_us{0}, write_us{0};

long elapsed_us(std::chrono::steady_clock::time_point since) {
  return static_cast<long>(std::chrono::duration_cast<std::chrono::microseconds>(
                               std::chrono::steady_clock::now() - since)
                               .count());
}

json folder_record(const DatasetSpec& spec) {
  return {{"format", "geardiag-dataset"},
          {"format_version", 1},
          {"spec_hash", spec.hash},
          {"recordings", spec.total},
          {"spec", spec.json}};
}

// Prepares DIR (rank 0 only): creates it, refuses a folder of another spec or one that is not a
// dataset, takes the lock, removes the temporary files a killed run left. Returns the lock's fd.
int prepare_folder(const fs::path& dir, const DatasetSpec& spec) {
  const fs::path record = dir / "dataset.json";
  std::error_code ec;
  if (fs::exists(record)) {
    const json old = diag::load_json_file(record);
    if (!old.is_object() || old.value("format", "") != "geardiag-dataset") {
      throw diag::InputError("-o " + dir.string() + ": dataset.json is not a geardiag dataset's");
    }
    if (old.value("spec_hash", "") != spec.hash) {
      throw diag::InputError("-o " + dir.string() +
                             ": this folder was made from a different spec (hash " +
                             old.value("spec_hash", "?") + ", this spec " + spec.hash +
                             "); use a new folder, or the spec it was made from");
    }
  } else if (fs::exists(dir)) {
    if (!fs::is_directory(dir)) {
      throw diag::InputError("-o " + dir.string() + ": exists and is not a folder");
    }
    if (!fs::is_empty(dir)) {
      throw diag::InputError("-o " + dir.string() +
                             ": the folder is not empty and holds no dataset.json (not a "
                             "geardiag dataset); use a new or empty folder");
    }
  }
  fs::create_directories(dir / "recordings", ec);
  if (ec) throw diag::InputError("-o " + dir.string() + ": cannot create: " + ec.message());
  const int fd = ::open((dir / ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0 || ::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (fd >= 0) ::close(fd);
    throw diag::InputError("-o " + dir.string() +
                           ": another geardiag dataset is writing this folder (.lock is held)");
  }
  if (!fs::exists(record)) {
    diag::write_output_file(record, folder_record(spec).dump(1) + "\n", "-o");
  }
  // A run killed with SIGKILL leaves "<id>.h5.tmp-<pid>" behind: never a complete file.
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "recordings")) {
    if (e.path().filename().string().find(".tmp-") != std::string::npos) fs::remove(e.path(), ec);
  }
  return fd;
}

// One recording, simulated and written.
void generate(const DatasetSpec& spec, const DrawnRecording& d, const fs::path& file,
              std::set<std::string>& warnings, std::mutex& warnings_mutex) {
  const auto start = std::chrono::steady_clock::now();
  const DatasetSimulator& simulator = simulator_of(spec);
  std::vector<std::string> sim_warnings;
  diag::Recording rec = simulator.simulate(spec, d, sim_warnings);
  json truth = json::parse(rec.truth_json);
  json row = manifest_row(spec, d);
  simulator.add_outcomes(truth, row);
  truth["dataset"] = {{"id", d.id},
                      {"class", d.cls},
                      {"index", d.index},
                      {"spec_hash", spec.hash},
                      {"scenario", simulator.model(d)},
                      {"manifest", row}};
  rec.truth_json = truth.dump();
  rec.metadata["dataset_id"] = d.id;
  rec.metadata["dataset_class"] = d.cls;
  {
    const std::lock_guard<std::mutex> lock(warnings_mutex);
    warnings.insert(sim_warnings.begin(), sim_warnings.end());
  }
  simulate_us += elapsed_us(start);
  const std::lock_guard<std::mutex> lock(hdf5_mutex);
  const auto write_start = std::chrono::steady_clock::now();
  diag::write_recording(file, rec);
  write_us += elapsed_us(write_start);
}

// '1' for each recording whose file exists under its final name (complete), else '0'.
std::string complete_recordings(const fs::path& dir, const DatasetSpec& spec) {
  std::set<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "recordings")) {
    names.insert(e.path().filename().string());
  }
  std::string done(spec.total, '0');
  for (std::size_t k = 0; k < spec.total; ++k) {
    if (names.count(draw_recording(spec, k).id + ".h5")) done[k] = '1';
  }
  return done;
}

std::string csv_cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  }
  return v.dump();
}

// The manifest (CSV and JSON lines, the same columns) and the class-balance summary of the
// complete recordings. Returns the number of complete recordings.
std::size_t write_manifest(const fs::path& dir, const DatasetSpec& spec, std::ostream& out) {
  const std::vector<std::string> cols = manifest_columns(spec);
  std::ostringstream csv, jsonl;
  for (std::size_t i = 0; i < cols.size(); ++i) csv << (i ? "," : "") << cols[i];
  csv << "\n";
  std::map<std::string, std::pair<std::size_t, std::size_t>> per_class;  // complete, planned
  std::map<std::string, std::size_t> per_fault;
  std::size_t complete = 0;
  for (const DatasetClass& c : spec.classes) per_class[c.name] = {0, 0};
  const std::string done = complete_recordings(dir, spec);
  for (std::size_t k = 0; k < spec.total; ++k) {
    const DrawnRecording d = draw_recording(spec, k);
    ++per_class[d.cls].second;
    if (done[k] != '1') continue;
    ++per_class[d.cls].first;
    ++complete;
    for (const DrawnFault& f : d.faults) {  // a bearing fault: where and which
      ++per_fault[f.type == "bearing" ? f.type + " " + f.bearing + " " + f.bearing_fault
                                      : f.type + " " + f.gear];
    }
    for (const DrawnDefect& f : d.defects) ++per_fault[f.type + " " + f.gear];
    // A row holding the simulation's outcome (face gear: DLF, impact class): read back from the
    // file.
    const json row = simulator_of(spec).has_outcomes()
                         ? json::parse(diag::RecordingReader(dir / ("recordings/" + d.id + ".h5"))
                                           .truth_json())["dataset"]["manifest"]
                         : manifest_row(spec, d);
    jsonl << "{";
    for (std::size_t i = 0; i < cols.size(); ++i) {
      csv << (i ? "," : "") << csv_cell(row[cols[i]]);
      jsonl << (i ? "," : "") << json(cols[i]).dump() << ":" << row[cols[i]].dump();
    }
    csv << "\n";
    jsonl << "}\n";
  }
  diag::write_output_file(dir / "manifest.csv", csv.str(), "manifest.csv");
  diag::write_output_file(dir / "manifest.jsonl", jsonl.str(), "manifest.jsonl");
  json summary = {{"spec_hash", spec.hash},
                  {"recordings", complete},
                  {"planned", spec.total},
                  {"classes", json::object()},
                  {"faults", per_fault}};
  out << "class balance (complete / planned):\n";
  for (const DatasetClass& c : spec.classes) {
    const auto [done, planned] = per_class[c.name];
    summary["classes"][c.name] = {{"recordings", done}, {"planned", planned}};
    out << "  " << c.name << std::string(c.name.size() < 20 ? 20 - c.name.size() : 1, ' ') << done
        << " / " << planned << "\n";
  }
  diag::write_output_file(dir / "summary.json", summary.dump(1) + "\n", "summary.json");
  return complete;
}

}  // namespace

int cmd_dataset(int argc, char** argv) {
  std::string spec_file, out_dir;
  int jobs = 0;
  po::options_description desc(
      "geardiag dataset SPEC.json -o DIR [--jobs N]\n"
      "mpirun -np N geardiag dataset SPEC.json -o DIR\n\n"
      "Generates a labelled synthetic dataset: DIR/recordings/<id>.h5 (each with its /truth),\n"
      "DIR/manifest.csv and DIR/manifest.jsonl (one row per complete recording: file, class and\n"
      "every drawn parameter), DIR/summary.json (class balance). Recording k depends only on\n"
      "(seed, k): the same bytes whatever --jobs or the number of MPI ranks. Run the same\n"
      "command again to resume after an interruption; a folder made from another spec is\n"
      "refused. Spec format: docs/cli/dataset.md.\n\noptions");
  desc.add_options()("help,h", "this help")("spec", po::value(&spec_file)->required(),
                                            "dataset spec (JSON)")(
      "output,o", po::value(&out_dir)->required(), "output folder")(
      "jobs,j", po::value(&jobs)->default_value(0),
      "worker threads per process; 0 = every core (shared by the ranks on a node)");
  po::positional_options_description pos;
  pos.add("spec", 1);
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm, &pos)) return 0;
  MpiWorld world(&argc, &argv);
  jobs = resolve_jobs(jobs);
  // Every rank reads and checks the spec (the same file, the same verdict): nothing is written
  // before it passed.
  const DatasetSpec spec = load_dataset_spec(spec_file);
  const fs::path dir(out_dir);
  int lock_fd = -1;
  std::string refusal;
  if (world.root()) {
    for (const diag::Gearbox& gb : spec.gearboxes) print_warnings(gb.warnings(), "dataset");
    print_warnings(spec.warnings, "dataset");
    try {
      lock_fd = prepare_folder(dir, spec);
    } catch (const diag::InputError& e) {
      refusal = e.what();
    }
  }
  if (world.max(refusal.empty() ? 0 : 1) != 0) {
    if (world.root()) throw diag::InputError(refusal);
    return 2;
  }
  // Which recordings are complete: rank 0 reads the folder once (one readdir, not a stat per
  // recording and rank: on a parallel file system the metadata server is the bottleneck) after
  // cleaning it, and tells the others before anyone writes.
  std::string done;
  if (world.root()) done = complete_recordings(dir, spec);
  world.broadcast(done);
  std::vector<std::size_t> mine;
  std::size_t missing = 0;
  for (std::size_t k = 0; k < spec.total; ++k) {
    if (done[k] == '1') continue;
    if (missing++ % static_cast<std::size_t>(world.size()) ==
        static_cast<std::size_t>(world.rank())) {
      mine.push_back(k);
    }
  }
  world.barrier();
  if (world.root() && missing < spec.total) {
    std::cout << "resuming: " << spec.total - missing << " of " << spec.total
              << " recordings already complete\n";
  }
  std::set<std::string> warnings;
  std::mutex warnings_mutex, errors_mutex;
  std::vector<std::string> errors;
  long input_errors = 0, internal_errors = 0;
  Progress progress("dataset", mine.size(), world.root());
  diag::parallel_for(mine.size(), jobs, [&](std::size_t i) {
    const DrawnRecording d = draw_recording(spec, mine[i]);
    try {
      generate(spec, d, dir / "recordings" / (d.id + ".h5"), warnings, warnings_mutex);
    } catch (const std::exception& e) {
      const std::lock_guard<std::mutex> lock(errors_mutex);
      (dynamic_cast<const diag::InputError*>(&e) ? input_errors : internal_errors)++;
      errors.push_back(d.id + ": " + e.what());
    }
    progress.tick();
  });
  progress.finish();
  for (const std::string& w : warnings) print_warnings({w}, "dataset");
  for (const std::string& e : errors) std::cerr << "geardiag dataset: error: " << e << "\n";
  const long failed_input = world.sum(input_errors), failed_internal = world.sum(internal_errors);
  const long sim_total = world.sum(simulate_us), write_total = world.sum(write_us);
  world.barrier();
  if (!world.root()) return failed_internal ? 3 : failed_input ? 2 : 0;
  const std::size_t complete = write_manifest(dir, spec, std::cout);
  std::cout << complete << " of " << spec.total << " recordings in " << dir.string()
            << " (manifest.csv, manifest.jsonl, summary.json)\n";
  if (missing > 0) {
    std::cout << "CPU per new recording: simulation " << sim_total / 1e6 / missing << " s, writing "
              << write_total / 1e6 / missing << " s (one writer per process)\n";
  }
  if (lock_fd >= 0) ::close(lock_fd);
  if (failed_internal || failed_input) {
    std::cerr << "geardiag dataset: " << failed_input + failed_internal
              << " recording(s) failed (above); run the same command again to retry them\n";
    return failed_internal ? 3 : 2;
  }
  return 0;
}

}  // namespace geardiag
