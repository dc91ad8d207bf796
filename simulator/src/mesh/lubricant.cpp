#include "sim/mesh/lubricant.hpp"

#include <cmath>
#include <sstream>

#include "diag/error.hpp"
#include "diag/range_check.hpp"

namespace sim {

using diag::InputError;

namespace {

constexpr double kKelvin = 273.15;
constexpr double kWaltherShift = 0.7;      // ASTM D341: nu + 0.7 [cSt]
constexpr double kExpansionPerK = 6.4e-4;  // beta of mineral oils [1/K]
constexpr double kMinTemperatureC = -30.0;
constexpr double kMaxTemperatureC = 150.0;

double walther_y(double nu_cst) { return std::log10(std::log10(nu_cst + kWaltherShift)); }
double walther_x(double t_c) { return std::log10(t_c + kKelvin); }

void check_temperature(double t_c, const char* where) {
  diag::require_range(std::isfinite(t_c) && t_c >= kMinTemperatureC && t_c <= kMaxTemperatureC,
                      where, "temperature_c", t_c,
                      "[-30, 150] degC (range of the ASTM D341 viscosity law)");
}

}  // namespace

Lubricant Lubricant::iso_vg(int grade) {
  // nu100 of a VI-95 mineral oil per ASTM D2270 (see the header).
  double nu100 = 0;
  switch (grade) {
    case 68:
      nu100 = 8.53;
      break;
    case 100:
      nu100 = 11.07;
      break;
    case 150:
      nu100 = 14.55;
      break;
    case 220:
      nu100 = 18.75;
      break;
    case 320:
      nu100 = 23.95;
      break;
    default: {
      std::ostringstream m;
      m << grade << " has no preset: use 68, 100, 150, 220 or 320, or give nu40/nu100";
      throw InputError(diag::format_error("Lubricant::iso_vg", "grade", m.str()));
    }
  }
  Lubricant oil;
  oil.nu40_cst = grade;
  oil.nu100_cst = nu100;
  oil.density15_kg_per_m3 = 890.0;
  return oil;
}

Lubricant Lubricant::from_two_points(double t_a_c, double nu_a_cst, double t_b_c, double nu_b_cst,
                                     double density15_kg_per_m3) {
  const char* where = "Lubricant::from_two_points";
  check_temperature(t_a_c, where);
  check_temperature(t_b_c, where);
  diag::require_range(std::abs(t_a_c - t_b_c) >= 1.0, where, "t_b_c", t_b_c,
                      "at least 1 degC away from t_a_c");
  diag::require_range(std::isfinite(nu_a_cst) && nu_a_cst >= 2.0, where, "nu_a_cst", nu_a_cst,
                      ">= 2 cSt");
  diag::require_range(std::isfinite(nu_b_cst) && nu_b_cst >= 2.0, where, "nu_b_cst", nu_b_cst,
                      ">= 2 cSt");
  const double b =
      (walther_y(nu_a_cst) - walther_y(nu_b_cst)) / (walther_x(t_b_c) - walther_x(t_a_c));
  const double a = walther_y(nu_a_cst) + b * walther_x(t_a_c);
  const auto at = [&](double t_c) {
    return std::pow(10.0, std::pow(10.0, a - b * walther_x(t_c))) - kWaltherShift;
  };
  Lubricant oil;
  oil.nu40_cst = at(40.0);
  oil.nu100_cst = at(100.0);
  oil.density15_kg_per_m3 = density15_kg_per_m3;
  oil.validate(where);
  return oil;
}

double Lubricant::walther_b() const {
  return (walther_y(nu40_cst) - walther_y(nu100_cst)) / (walther_x(100.0) - walther_x(40.0));
}

double Lubricant::walther_a() const { return walther_y(nu40_cst) + walther_b() * walther_x(40.0); }

double Lubricant::kinematic_viscosity_cst(double temperature_c) const {
  check_temperature(temperature_c, "Lubricant::kinematic_viscosity_cst");
  // Evaluated as an interpolation between the reference points in Walther coordinates, so that
  // 40 and 100 degC give nu40 and nu100 to the last bit (no A - B x cancellation).
  const double x40 = walther_x(40.0), x100 = walther_x(100.0);
  const double y40 = walther_y(nu40_cst), y100 = walther_y(nu100_cst);
  const double w = (walther_x(temperature_c) - x40) / (x100 - x40);
  const double y = y40 + w * (y100 - y40);
  return std::pow(10.0, std::pow(10.0, y)) - kWaltherShift;
}

double Lubricant::density_kg_per_m3(double temperature_c) const {
  check_temperature(temperature_c, "Lubricant::density_kg_per_m3");
  return density15_kg_per_m3 * (1.0 - kExpansionPerK * (temperature_c - 15.0));
}

double Lubricant::dynamic_viscosity_pa_s(double temperature_c) const {
  return kinematic_viscosity_cst(temperature_c) * 1e-6 * density_kg_per_m3(temperature_c);
}

void Lubricant::validate(const std::string& where) const {
  diag::require_range(std::isfinite(nu100_cst) && nu100_cst >= 2.0, where, "nu100_cst", nu100_cst,
                      ">= 2 cSt (ASTM D341 range)");
  diag::require_range(std::isfinite(nu40_cst) && nu40_cst > nu100_cst, where, "nu40_cst", nu40_cst,
                      "> nu100_cst (viscosity falls with temperature)");
  diag::require_range(std::isfinite(density15_kg_per_m3) && density15_kg_per_m3 >= 700.0 &&
                          density15_kg_per_m3 <= 1200.0,
                      where, "density15_kg_per_m3", density15_kg_per_m3, "[700, 1200] kg/m^3");
}

}  // namespace sim
