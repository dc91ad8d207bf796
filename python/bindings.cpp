// The compiled half of the Python module geardiag (python/geardiag/__init__.py is the other):
// pybind11 bindings over the same libraries as the CLI. Arrays cross without copies where the
// C++ side allows it: inputs are read in place (py::array_t, C-contiguous float64; another dtype
// or layout is converted once), and results own their std::vector through a capsule, so numpy
// reads the C++ buffer itself. The GIL is released in every computation. A diag::InputError
// becomes geardiag.InputError (a ValueError) with the same message.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "detect/analysis/analyze_file.hpp"
#include "detect/angular/order_spectrum.hpp"
#include "detect/angular/resample.hpp"
#include "detect/angular/tsa.hpp"
#include "detect/attribution/period_matcher.hpp"
#include "detect/indicators/indicators.hpp"
#include "detect/spectral/envelope.hpp"
#include "detect/spectral/kurtogram.hpp"
#include "detect/spectral/spectrum.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/data_groups.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/io/open_recording.hpp"
#include "diag/io/truth.hpp"
#include "report/curves.hpp"
#include "report/html_report.hpp"
#include "report/report.hpp"
#include "sim/dynamics/scenario.hpp"
#include "sim/dynamics/simulate.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace py = pybind11;

namespace {

using InArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Release = py::gil_scoped_release;

// A numpy array over the vector's own buffer: the vector moves into a capsule that numpy frees.
py::array_t<double> to_numpy(std::vector<double>&& v) {
  auto* owned = new std::vector<double>(std::move(v));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>(static_cast<py::ssize_t>(owned->size()), owned->data(), owner);
}

// A 1-D view of an input array (no copy for C-contiguous float64).
std::span<const double> view(const InArray& a, const char* name) {
  if (a.ndim() != 1) {
    throw diag::InputError(std::string(name) + ": must be a 1-D array, not " +
                           std::to_string(a.ndim()) + "-D");
  }
  return {a.data(), static_cast<std::size_t>(a.shape(0))};
}

py::object json_to_py(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json py_to_json(const py::handle& o, const std::string& where) {
  const std::string text = py::str(py::module_::import("json").attr("dumps")(o));
  return diag::parse_json_text(text, where);
}

// ---- recordings: a dict of plain values and numpy arrays (the Python layer wraps it) ----

py::dict signal_to_py(diag::Signal&& s) {
  py::dict d;
  d["name"] = s.name;
  d["fs_hz"] = s.fs_hz;
  d["unit"] = s.unit;
  d["direction"] = std::string(diag::to_string(s.direction));
  d["location"] = s.location;
  d["role"] = std::string(diag::to_string(s.role));
  d["shaft"] = s.shaft;
  d["mesh"] = s.mesh;
  d["ppr"] = s.ppr;
  d["samples"] = to_numpy(std::move(s.samples));
  return d;
}

py::dict recording_to_py(diag::Recording&& rec) {
  py::list signals, tachos;
  for (diag::Signal& s : rec.signals) signals.append(signal_to_py(std::move(s)));
  for (diag::Signal& s : rec.tachos) tachos.append(signal_to_py(std::move(s)));
  py::dict d;
  d["signals"] = signals;
  d["tachos"] = tachos;
  d["gearbox_json"] = rec.gearbox_json;
  d["truth_json"] = rec.truth_json;
  d["metadata"] = rec.metadata;
  d["speed_rpm"] = rec.speed_rpm;
  d["notes"] = rec.notes;
  d["roles_stated"] = rec.roles_stated;
  return d;
}

diag::Signal signal_from_py(const py::dict& d, const std::string& where) {
  diag::Signal s;
  s.name = d["name"].cast<std::string>();
  const std::string w = where + ": " + s.name;
  s.fs_hz = d["fs_hz"].cast<double>();
  s.unit = d.contains("unit") ? d["unit"].cast<std::string>() : "";
  if (d.contains("direction")) {
    s.direction = diag::direction_from_string(d["direction"].cast<std::string>());
  }
  s.location = d.contains("location") ? d["location"].cast<std::string>() : "";
  if (d.contains("role")) s.role = diag::role_from_string(d["role"].cast<std::string>());
  s.shaft = d.contains("shaft") ? d["shaft"].cast<std::string>() : "";
  s.mesh = d.contains("mesh") ? d["mesh"].cast<std::string>() : "";
  s.ppr = d.contains("ppr") ? d["ppr"].cast<int>() : 0;
  const InArray a = InArray::ensure(d["samples"]);
  if (!a) throw diag::InputError(w + ": samples: not a numeric array");
  const std::span<const double> x = view(a, "samples");
  s.samples.assign(x.begin(), x.end());
  return s;
}

diag::Recording recording_from_py(const py::dict& d) {
  diag::Recording rec;
  for (const py::handle& s : d["signals"].cast<py::list>()) {
    rec.signals.push_back(signal_from_py(s.cast<py::dict>(), "signals"));
  }
  if (d.contains("tachos")) {
    for (const py::handle& s : d["tachos"].cast<py::list>()) {
      rec.tachos.push_back(signal_from_py(s.cast<py::dict>(), "tachos"));
    }
  }
  if (d.contains("gearbox_json")) rec.gearbox_json = d["gearbox_json"].cast<std::string>();
  if (d.contains("truth_json")) rec.truth_json = d["truth_json"].cast<std::string>();
  if (d.contains("metadata")) {
    rec.metadata = d["metadata"].cast<std::map<std::string, std::string>>();
  }
  if (d.contains("speed_rpm")) rec.speed_rpm = d["speed_rpm"].cast<double>();
  if (d.contains("notes")) rec.notes = d["notes"].cast<std::vector<std::string>>();
  if (d.contains("roles_stated")) rec.roles_stated = d["roles_stated"].cast<bool>();
  return rec;
}

// A recording to analyse: a Recording's dict (in memory) or a path (read by the analysis).
detect::RecordingInput recording_input(const py::object& src) {
  if (py::isinstance<py::dict>(src)) {
    return detect::RecordingInput(
        std::make_shared<const diag::Recording>(recording_from_py(src.cast<py::dict>())));
  }
  return detect::RecordingInput(
      std::string(py::str(py::module_::import("os").attr("fspath")(src))));
}

// ---- gearbox ----

diag::Gearbox gearbox_from(const py::object& src) {
  if (py::isinstance<diag::Gearbox>(src)) return src.cast<diag::Gearbox>();
  if (py::isinstance<py::dict>(src))
    return diag::parse_gearbox(py_to_json(src, "gearbox"), "gearbox");
  const std::string path = py::str(py::module_::import("os").attr("fspath")(src));
  return diag::load_gearbox(path);
}

py::list shafts_py(const diag::Gearbox& gb) {
  py::list out;
  for (std::size_t i = 0; i < gb.shafts().size(); ++i) {
    const diag::Shaft& s = gb.shafts()[i];
    py::list gears;
    for (int g : s.gears) gears.append(gb.gears()[static_cast<std::size_t>(g)].name);
    py::dict d;
    d["name"] = s.name;
    d["speed_ratio"] = s.speed_ratio;
    d["speed_hz"] = gb.shaft_speed_hz(static_cast<int>(i));
    d["speed_rpm"] = gb.shaft_speed_rpm(static_cast<int>(i));
    d["period_input_rev"] = gb.shaft_period_input_rev(static_cast<int>(i));
    d["gears"] = gears;
    out.append(d);
  }
  return out;
}

py::list gears_py(const diag::Gearbox& gb) {
  py::list out;
  for (std::size_t i = 0; i < gb.gears().size(); ++i) {
    const diag::GearEntry& g = gb.gears()[i];
    const int gi = static_cast<int>(i);
    py::dict d;
    d["name"] = g.name;
    d["shaft"] = g.shaft;
    d["teeth"] = g.spec.teeth;
    d["on_power_path"] = gb.on_power_path(gi);
    if (gb.on_power_path(gi)) {
      d["ratio_to_output"] = gb.ratio_to_output(gi);
      d["recurrence_period_input_rev"] = gb.recurrence_period_input_rev(gi);
    }
    out.append(d);
  }
  return out;
}

py::list meshes_py(const diag::Gearbox& gb) {
  py::list out;
  for (std::size_t i = 0; i < gb.meshes().size(); ++i) {
    const diag::Mesh& m = gb.meshes()[i];
    const int mi = static_cast<int>(i);
    py::dict d;
    d["name"] = diag::mesh_name(gb, mi);
    d["driver"] = gb.gears()[static_cast<std::size_t>(m.driver)].name;
    d["driven"] = gb.gears()[static_cast<std::size_t>(m.driven)].name;
    d["frequency_hz"] = gb.mesh_frequency_hz(mi);
    d["hunting_period_input_rev"] = gb.hunting_period_input_rev(mi);
    out.append(d);
  }
  return out;
}

// ---- option parsing shared by the spectral functions ----

detect::Detrend detrend_from(const std::string& s) {
  if (s == "constant") return detect::Detrend::kConstant;
  if (s == "linear") return detect::Detrend::kLinear;
  if (s == "none" || s.empty()) return detect::Detrend::kNone;
  throw diag::InputError("welch: detrend: '" + s + "' is not constant, linear or none");
}

detect::AmplitudeScaling amplitude_scaling_from(const std::string& s, const char* fn) {
  if (s == "peak") return detect::AmplitudeScaling::kPeak;
  if (s == "rms") return detect::AmplitudeScaling::kRms;
  throw diag::InputError(std::string(fn) + ": scaling: '" + s + "' is not peak or rms");
}

py::tuple pair(std::vector<double>&& x, std::vector<double>&& y) {
  return py::make_tuple(to_numpy(std::move(x)), to_numpy(std::move(y)));
}

py::dict time_indicators(std::span<const double> x) {
  detect::Moments mo;
  {
    Release nogil;
    mo = detect::moments(x);
  }
  py::dict d;
  d["rms"] = mo.rms();
  d["peak"] = mo.peak();
  d["peak_to_peak"] = mo.peak_to_peak();
  d["crest_factor"] = mo.crest_factor();
  d["kurtosis"] = mo.kurtosis();
  d["skewness"] = mo.skewness();
  return d;
}

// Keyword options by name: each key must be one of `setters`; the setter stores the value.
using H = const py::handle&;
void apply_options(const py::dict& options, const std::string& fn,
                   const std::map<std::string, std::function<void(H)>>& setters) {
  for (const auto& [k, v] : options) {
    const std::string key = py::str(k);
    const auto it = setters.find(key);
    if (it == setters.end()) throw diag::InputError(fn + ": unknown option '" + key + "'");
    it->second(v);
  }
}

py::dict curves_py(std::vector<diag::DataGroup>&& groups) {
  py::dict out;
  for (diag::DataGroup& g : groups) {
    py::dict columns, units;
    for (diag::DataColumn& c : g.columns) {
      units[py::str(c.name)] = c.unit;
      py::array a = to_numpy(std::move(c.values));
      if (!c.shape.empty()) a = a.reshape(std::vector<py::ssize_t>(c.shape.begin(), c.shape.end()));
      columns[py::str(c.name)] = a;
    }
    py::dict attrs;
    for (const auto& [k, v] : g.numbers) attrs[py::str(k)] = v;
    for (const auto& [k, v] : g.texts) attrs[py::str(k)] = v;
    py::dict d;
    d["columns"] = columns;
    d["units"] = units;
    d["attrs"] = attrs;
    d["description"] = g.description;
    out[py::str(g.path)] = d;
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_geardiag, m) {
  m.doc() = "geardiag: gear and bearing vibration diagnostics (compiled part)";
  py::register_exception<diag::InputError>(m, "InputError", PyExc_ValueError);

  // ---- recordings ----
  m.def(
      "parse_truth",
      [](const std::string& truth_json) -> py::object {
        // diag/io/truth.hpp: checked (InputError naming the field) and in its one layout.
        const auto t = diag::parse_truth(truth_json, "truth");
        return t ? json_to_py(t->to_json()) : py::none();
      },
      py::arg("truth_json"));
  m.def(
      "read_recording",
      [](const std::string& path, std::optional<double> fs_hz) {
        diag::Recording rec;
        {
          Release nogil;
          diag::OpenOptions o;
          o.fs_hz = fs_hz;
          rec = diag::open_recording(path, o);
        }
        return recording_to_py(std::move(rec));
      },
      py::arg("path"), py::arg("fs_hz") = py::none());
  m.def(
      "write_recording",
      [](const std::string& path, const py::dict& rec) {
        const diag::Recording r = recording_from_py(rec);
        Release nogil;
        diag::write_recording(path, r);
      },
      py::arg("path"), py::arg("recording"));

  // ---- gearbox ----
  py::class_<diag::Gearbox>(m, "Gearbox")
      .def_static("from_json", &gearbox_from, py::arg("source"),
                  "A gearbox description from a JSON file path or a dict (docs/formats.md).")
      .def_property_readonly("name", &diag::Gearbox::name)
      .def_property_readonly(
          "input_shaft", [](const diag::Gearbox& gb) { return gb.shafts()[gb.input_shaft()].name; })
      .def_property_readonly(
          "output_shaft",
          [](const diag::Gearbox& gb) { return gb.shafts()[gb.output_shaft()].name; })
      .def_property_readonly("input_speed_rpm",
                             [](const diag::Gearbox& gb) { return gb.input().speed_rpm; })
      .def_property_readonly("total_ratio", &diag::Gearbox::total_ratio)
      .def_property_readonly("shafts", &shafts_py)
      .def_property_readonly("gears", &gears_py)
      .def_property_readonly("meshes", &meshes_py)
      .def_property_readonly("warnings", &diag::Gearbox::warnings)
      .def_property_readonly("json", &diag::Gearbox::description_json)
      .def("summary", [](const diag::Gearbox& gb) { return json_to_py(diag::summary_json(gb)); })
      .def("with_input_speed_rpm", &diag::Gearbox::with_input_speed_rpm, py::arg("speed_rpm"))
      .def("__repr__", [](const diag::Gearbox& gb) { return diag::format_summary(gb); });

  // ---- spectral ----
  m.def(
      "welch",
      [](const InArray& x, double fs_hz, std::size_t nperseg, long long noverlap, std::size_t nfft,
         const std::string& window, const std::string& detrend, const std::string& scaling) {
        detect::WelchOptions o;
        o.fs_hz = fs_hz;
        o.nperseg = nperseg;
        o.noverlap = noverlap;
        o.nfft = nfft;
        o.window = detect::parse_window(window);
        o.detrend = detrend_from(detrend);
        if (scaling != "density" && scaling != "spectrum") {
          throw diag::InputError("welch: scaling: '" + scaling + "' is not density or spectrum");
        }
        o.scaling =
            scaling == "density" ? detect::PsdScaling::kDensity : detect::PsdScaling::kSpectrum;
        const std::span<const double> v = view(x, "x");
        detect::Psd p;
        {
          Release nogil;
          p = detect::welch(v, o);
        }
        return pair(std::move(p.frequency_hz), std::move(p.value));
      },
      py::arg("x"), py::arg("fs_hz"), py::arg("nperseg") = 256, py::arg("noverlap") = -1,
      py::arg("nfft") = 0, py::arg("window") = "hann", py::arg("detrend") = "constant",
      py::arg("scaling") = "density");
  m.def(
      "spectrum",
      [](const InArray& x, double fs_hz, const std::string& window, const std::string& scaling,
         std::size_t nfft, bool remove_mean) {
        detect::SpectrumOptions o;
        o.fs_hz = fs_hz;
        o.window = detect::parse_window(window);
        o.scaling = amplitude_scaling_from(scaling, "spectrum");
        o.nfft = nfft;
        o.remove_mean = remove_mean;
        const std::span<const double> v = view(x, "x");
        detect::Spectrum s;
        {
          Release nogil;
          s = detect::amplitude_spectrum(v, o);
        }
        return pair(std::move(s.frequency_hz), std::move(s.amplitude));
      },
      py::arg("x"), py::arg("fs_hz"), py::arg("window") = "flattop", py::arg("scaling") = "peak",
      py::arg("nfft") = 0, py::arg("remove_mean") = false);
  m.def(
      "envelope",
      [](const InArray& x) {
        const std::span<const double> v = view(x, "x");
        std::vector<double> e;
        {
          Release nogil;
          e = detect::envelope(v);
        }
        return to_numpy(std::move(e));
      },
      py::arg("x"));
  m.def(
      "envelope_spectrum",
      [](const InArray& x, double fs_hz, double band_low_hz, double band_high_hz,
         const std::string& window, const std::string& scaling) {
        detect::EnvelopeSpectrumOptions o;
        o.fs_hz = fs_hz;
        o.band_low_hz = band_low_hz;
        o.band_high_hz = band_high_hz;
        o.window = detect::parse_window(window);
        o.scaling = amplitude_scaling_from(scaling, "envelope_spectrum");
        const std::span<const double> v = view(x, "x");
        detect::Spectrum s;
        {
          Release nogil;
          s = detect::envelope_spectrum(v, o);
        }
        return pair(std::move(s.frequency_hz), std::move(s.amplitude));
      },
      py::arg("x"), py::arg("fs_hz"), py::arg("band_low_hz") = 0.0, py::arg("band_high_hz") = 0.0,
      py::arg("window") = "rectangular", py::arg("scaling") = "peak");
  m.def(
      "kurtogram",
      [](const InArray& x, double fs_hz, int max_level) {
        detect::KurtogramOptions o;
        o.fs_hz = fs_hz;
        o.max_level = max_level;
        const std::span<const double> v = view(x, "x");
        detect::Kurtogram k;
        {
          Release nogil;
          k = detect::fast_kurtogram(v, o);
        }
        py::list levels;
        for (detect::KurtogramLevel& l : k.levels) {
          py::dict d;
          d["level"] = l.level;
          d["bandwidth_hz"] = l.bandwidth_hz;
          d["kurtosis"] = to_numpy(std::move(l.kurtosis));
          levels.append(d);
        }
        py::dict d;
        d["levels"] = levels;
        d["centre_hz"] = k.centre_hz;
        d["bandwidth_hz"] = k.bandwidth_hz;
        d["level"] = k.level;
        d["kurtosis"] = k.kurtosis;
        d["low_hz"] = k.low_hz();
        d["high_hz"] = k.high_hz();
        return d;
      },
      py::arg("x"), py::arg("fs_hz"), py::arg("max_level") = 6);

  // ---- angular ----
  m.def(
      "tsa",
      [](const InArray& x, double fs_hz, const InArray& pulse_times_s, int samples_per_rev,
         int min_revolutions, int pulses_per_rev, std::optional<std::vector<int>> mesh_orders) {
        detect::TsaOptions o;
        o.samples_per_rev = samples_per_rev;
        o.min_revolutions = min_revolutions;
        o.pulses_per_rev = pulses_per_rev;
        const std::span<const double> v = view(x, "x");
        const std::span<const double> p = view(pulse_times_s, "pulse_times_s");
        detect::Tsa t;
        std::vector<double> regular, residual, difference;
        {
          Release nogil;
          t = detect::tsa(v, fs_hz, p, o);
          if (mesh_orders) {
            regular = detect::tsa_regular(t, *mesh_orders);
            residual = detect::tsa_residual(t, *mesh_orders);
            difference = detect::tsa_difference(t, *mesh_orders);
          }
        }
        py::dict d;
        d["revolutions"] = t.revolutions;
        d["samples_per_rev"] = t.samples_per_rev;
        d["first_rev"] = t.first_rev;
        d["tsa"] = to_numpy(std::move(t.samples));
        if (mesh_orders) {
          d["regular"] = to_numpy(std::move(regular));
          d["residual"] = to_numpy(std::move(residual));
          d["difference"] = to_numpy(std::move(difference));
        }
        return d;
      },
      py::arg("x"), py::arg("fs_hz"), py::arg("pulse_times_s"), py::arg("samples_per_rev") = 1024,
      py::arg("min_revolutions") = 10, py::arg("pulses_per_rev") = 1,
      py::arg("mesh_orders") = py::none());
  m.def(
      "order_spectrum",
      [](const InArray& x, double fs_hz, const InArray& pulse_times_s, int samples_per_rev,
         int pulses_per_rev, int segment_revs, double overlap, const std::string& window) {
        detect::ResampleOptions ro;
        ro.samples_per_rev = samples_per_rev;
        ro.pulses_per_rev = pulses_per_rev;
        detect::OrderSpectrumOptions o;
        o.segment_revs = segment_revs;
        o.overlap = overlap;
        if (window != "hann" && window != "rectangular") {
          throw diag::InputError("order_spectrum: window: '" + window +
                                 "' is not hann or rectangular");
        }
        o.window = window == "hann" ? detect::OrderSpectrumOptions::Window::kHann
                                    : detect::OrderSpectrumOptions::Window::kRectangular;
        const std::span<const double> v = view(x, "x");
        const std::span<const double> p = view(pulse_times_s, "pulse_times_s");
        detect::OrderSpectrum s;
        {
          Release nogil;
          s = detect::order_spectrum(detect::resample_by_angle(v, fs_hz, p, ro), o);
        }
        return pair(std::move(s.order), std::move(s.amplitude));
      },
      py::arg("x"), py::arg("fs_hz"), py::arg("pulse_times_s"), py::arg("samples_per_rev") = 256,
      py::arg("pulses_per_rev") = 1, py::arg("segment_revs") = 0, py::arg("overlap") = 0.5,
      py::arg("window") = "hann");

  // ---- indicators ----
  m.def(
      "indicators",
      [](const InArray& x, int mesh_order, std::optional<std::vector<int>> mesh_orders,
         int mesh_harmonics, int ser_sidebands) {
        const std::span<const double> v = view(x, "x");
        py::dict d = time_indicators(v);
        if (mesh_order <= 0) return d;
        const std::vector<int> orders = mesh_orders ? *mesh_orders : std::vector<int>{mesh_order};
        detect::GearMetricOptions gm;
        gm.mesh_order = mesh_order;
        gm.mesh_harmonics = mesh_harmonics;
        gm.ser_sidebands = ser_sidebands;
        detect::GearIndicators g;
        {
          Release nogil;
          const std::vector<double> regular = detect::tsa_regular(v, orders);
          const std::vector<double> residual = detect::tsa_residual(v, orders);
          const std::vector<double> difference = detect::tsa_difference(v, orders);
          g = detect::gear_indicators({v, difference, regular, residual}, gm);
        }
        d["fm0"] = g.fm0;
        d["fm4"] = g.fm4;
        d["m6a"] = g.m6a;
        d["m8a"] = g.m8a;
        d["na4"] = g.na4;
        d["er"] = g.er;
        d["ser"] = g.ser;
        d["slf"] = g.slf;
        d["si"] = g.si;
        return d;
      },
      py::arg("x"), py::arg("mesh_order") = 0, py::arg("mesh_orders") = py::none(),
      py::arg("mesh_harmonics") = 3, py::arg("ser_sidebands") = 6);

  // ---- analysis ----
  m.def(
      "analyze",
      [](const py::object& source, const py::object& gearbox, std::optional<double> fs_hz,
         double rpm, const std::string& channel_map, const std::vector<std::string>& tachos,
         const py::list& baseline, const py::list& gear_baseline,
         std::optional<std::uint64_t> max_samples, std::optional<double> frame_seconds, bool html,
         const py::dict& options) {
        // Options first: a misspelt option is refused before a long read.
        detect::AnalyzeRequest request;
        detect::AnalyzeOptions& o = request.options;
        apply_options(
            options, "analyze",
            {{"welch_nperseg", [&](H v) { o.welch_nperseg = v.cast<std::size_t>(); }},
             {"kurtogram_max_level", [&](H v) { o.kurtogram_max_level = v.cast<int>(); }},
             {"tsa_min_revolutions", [&](H v) { o.tsa_min_revolutions = v.cast<int>(); }},
             {"tacho_pulses_per_rev", [&](H v) { o.tacho_pulses_per_rev = v.cast<int>(); }},
             {"mesh_harmonics", [&](H v) { o.sidebands.mesh_harmonics = v.cast<int>(); }},
             {"sidebands", [&](H v) { o.sidebands.sidebands = v.cast<int>(); }},
             {"peaks_reported", [&](H v) { o.peaks_reported = v.cast<int>(); }},
             {"threads", [&](H v) { o.threads = v.cast<int>(); }},
             {"plot_points", [&](H v) { o.plot_points = v.cast<int>(); }},
             {"envelope_plot_max_hz", [&](H v) { o.envelope_plot_max_hz = v.cast<double>(); }},
             {"nominal_time_s", [&](H v) { o.nominal_time_s = v.cast<double>(); }},
             {"speed_from_vibration", [&](H v) { o.speed_from_vibration = v.cast<bool>(); }},
             {"timing", [&](H v) { o.timing = v.cast<bool>(); }}});
        request.recording = recording_input(source);
        request.fs_hz = fs_hz;
        if (!gearbox.is_none()) request.gearbox = gearbox_from(gearbox);
        request.channels.channel_map = channel_map;
        request.channels.tachos = tachos;
        request.channels.rpm = rpm;
        for (const py::handle b : baseline) {
          request.baseline.push_back(recording_input(py::reinterpret_borrow<py::object>(b)));
        }
        for (const py::handle b : gear_baseline) {  // the first, then the more
          detect::RecordingInput in = recording_input(py::reinterpret_borrow<py::object>(b));
          if (!request.gear_baseline) {
            request.gear_baseline = std::move(in);
          } else {
            request.more_gear_baselines.push_back(std::move(in));
          }
        }
        if (max_samples) request.max_samples = *max_samples;
        if (frame_seconds) request.frame_s = *frame_seconds;
        detect::FileAnalysis a;
        std::vector<diag::DataGroup> curves;
        std::string page;
        {
          Release nogil;
          a = detect::analyze_file(request);
          curves = report::analysis_curves(a.result);
          if (html) {
            report::HtmlReportOptions ho;
            ho.source = request.recording.path.filename().string();
            ho.title = "geardiag analysis" + (ho.source.empty() ? "" : ": " + ho.source);
            page = report::render_html_report(a.result, ho);
          }
        }
        py::dict result = json_to_py(report::to_json(a.result));
        if (html) result["html"] = page;
        return py::make_tuple(result, curves_py(std::move(curves)));
      },
      py::arg("source"), py::arg("gearbox") = py::none(), py::arg("fs_hz") = py::none(),
      py::arg("rpm") = 0.0, py::arg("channel_map") = "",
      py::arg("tachos") = std::vector<std::string>{}, py::arg("baseline") = py::list(),
      py::arg("gear_baseline") = py::list(), py::arg("max_samples") = py::none(),
      py::arg("frame_seconds") = py::none(), py::arg("html") = false,
      py::arg("options") = py::dict());

  // ---- simulation ----
  m.def(
      "simulate",
      [](const py::object& gearbox, const py::object& scenario, std::optional<double> duration_s,
         std::optional<double> fs_hz, std::optional<std::uint64_t> seed) {
        const diag::Gearbox gb = gearbox_from(gearbox);
        sim::Scenario sc;
        if (py::isinstance<py::dict>(scenario)) {
          sc = sim::parse_scenario(py_to_json(scenario, "scenario"), "scenario");
        } else if (!scenario.is_none()) {
          sc = sim::load_scenario(
              std::string(py::str(py::module_::import("os").attr("fspath")(scenario))));
        }
        if (duration_s) sc.run.duration_s = *duration_s;
        if (fs_hz) sc.run.fs_hz = *fs_hz;
        if (seed) sc.dynamics.seed = sc.run.seed = *seed;
        diag::Recording rec;
        std::vector<std::string> warnings;
        {
          Release nogil;
          const sim::DynamicResult r = sim::simulate_dynamic(gb, sc.dynamics, sc.run);
          warnings = r.warnings;
          rec = sim::to_recording(gb, r);
        }
        py::dict d = recording_to_py(std::move(rec));
        d["warnings"] = warnings;
        return d;
      },
      py::arg("gearbox"), py::arg("scenario") = py::none(), py::arg("duration_s") = py::none(),
      py::arg("fs_hz") = py::none(), py::arg("seed") = py::none());
  m.def(
      "simulate_kinematic",
      [](const py::object& gearbox, double step_rad, double revolutions, double runout_output_rad,
         double mesh_te_output_rad, double noise_output_rad, double noise_input_rad,
         std::int64_t encoder_counts_per_rev, std::uint64_t seed) {
        const diag::Gearbox gb = gearbox_from(gearbox);
        sim::KinematicOptions k;
        k.step_rad = step_rad;
        k.revolutions = revolutions;
        k.runout_output_rad = runout_output_rad;
        k.mesh_te_output_rad = mesh_te_output_rad;
        k.noise_output_rad = noise_output_rad;
        k.noise_input_rad = noise_input_rad;
        k.encoder_counts_per_rev = encoder_counts_per_rev;
        k.seed = seed;
        diag::Recording rec;
        {
          Release nogil;
          rec = sim::to_recording(gb, sim::simulate_kinematic(gb, k));
        }
        return recording_to_py(std::move(rec));
      },
      py::arg("gearbox"), py::arg("step_rad") = 0.001, py::arg("revolutions") = 0.0,
      py::arg("runout_output_rad") = 0.0, py::arg("mesh_te_output_rad") = 0.0,
      py::arg("noise_output_rad") = 0.0, py::arg("noise_input_rad") = 0.0,
      py::arg("encoder_counts_per_rev") = 0, py::arg("seed") = 1);

  // ---- attribution ----
  m.def(
      "attribute",
      [](const InArray& input_angle, const InArray& output_angle, const py::object& gearbox,
         const py::dict& options) {
        const diag::Gearbox gb = gearbox_from(gearbox);
        detect::AttributionOptions o;
        apply_options(
            options, "attribute",
            {{"threshold_sigma", [&](H v) { o.threshold_sigma = v.cast<double>(); }},
             {"min_event_rad", [&](H v) { o.min_event_rad = v.cast<double>(); }},
             {"position_tolerance_rad", [&](H v) { o.position_tolerance_rad = v.cast<double>(); }},
             {"period_tolerance", [&](H v) { o.period_tolerance = v.cast<double>(); }},
             {"min_coverage", [&](H v) { o.min_coverage = v.cast<double>(); }},
             {"smooth_harmonics", [&](H v) { o.smooth_harmonics = v.cast<int>(); }},
             {"mesh_harmonics", [&](H v) { o.mesh_harmonics = v.cast<int>(); }},
             {"min_recurrences", [&](H v) { o.min_recurrences = v.cast<int>(); }}});
        const std::span<const double> in = view(input_angle, "input_angle");
        const std::span<const double> out = view(output_angle, "output_angle");
        detect::AttributionResult r;
        {
          Release nogil;
          r = detect::attribute_defects(in, out, gb, o);
        }
        return json_to_py(detect::to_json(r));
      },
      py::arg("input_angle"), py::arg("output_angle"), py::arg("gearbox"),
      py::arg("options") = py::dict());
}
