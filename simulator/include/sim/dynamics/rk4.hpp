// Classic fixed-step fourth-order Runge-Kutta for the gearbox model, with its work buffers
// allocated once. The first stage is evaluated with the observation (forces, powers, mesh
// states at the start of the step), so sensors cost nothing extra.
#pragma once

#include <vector>

#include "sim/dynamics/gearbox_model.hpp"

namespace sim {

class Rk4 {
 public:
  explicit Rk4(int state_size)
      : k1_(state_size), k2_(state_size), k3_(state_size), k4_(state_size), tmp_(state_size) {}

  // y(t) -> y(t + h) in place. `obs`, when given, receives the observation at (t, y(t)).
  void step(const GearboxModel& model, double t, double h, double* y, Observation* obs = nullptr) {
    const std::size_t n = k1_.size();
    model.derivatives(t, y, k1_.data(), obs);
    for (std::size_t i = 0; i < n; ++i) tmp_[i] = y[i] + 0.5 * h * k1_[i];
    model.derivatives(t + 0.5 * h, tmp_.data(), k2_.data());
    for (std::size_t i = 0; i < n; ++i) tmp_[i] = y[i] + 0.5 * h * k2_[i];
    model.derivatives(t + 0.5 * h, tmp_.data(), k3_.data());
    for (std::size_t i = 0; i < n; ++i) tmp_[i] = y[i] + h * k3_[i];
    model.derivatives(t + h, tmp_.data(), k4_.data());
    const double h6 = h / 6.0;
    for (std::size_t i = 0; i < n; ++i) y[i] += h6 * (k1_[i] + 2.0 * (k2_[i] + k3_[i]) + k4_[i]);
  }

 private:
  std::vector<double> k1_, k2_, k3_, k4_, tmp_;
};

}  // namespace sim
