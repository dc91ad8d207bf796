#include "detect/indicators/na4.hpp"

#include <limits>

#include "diag/error.hpp"

namespace detect {

namespace {

void require_record(std::span<const double> x, const char* where) {
  if (x.empty())
    throw diag::InputError(diag::format_error(where, "record", "empty (needs >= 1 sample)"));
}

// Population variance and fourth central moment (two passes).
struct Central {
  double var = 0, mu4 = 0;
};
Central central(std::span<const double> x) {
  const double n = static_cast<double>(x.size());
  double mean = 0;
  for (double v : x) mean += v;
  mean /= n;
  Central c;
  for (double v : x) {
    const double d2 = (v - mean) * (v - mean);
    c.var += d2;
    c.mu4 += d2 * d2;
  }
  c.var /= n;
  c.mu4 /= n;
  return c;
}

}  // namespace

void Na4Ensemble::add(std::span<const double> record) {
  require_record(record, "Na4Ensemble::add");
  variance_sum_ += central(record).var;
  ++records_;
}

double Na4Ensemble::mean_variance() const {
  if (records_ == 0)
    throw diag::InputError(
        diag::format_error("Na4Ensemble", "records", "empty ensemble: add() a record first"));
  return variance_sum_ / static_cast<double>(records_);
}

double Na4Ensemble::value(std::span<const double> current) const {
  require_record(current, "Na4Ensemble::value");
  const double v = mean_variance();
  if (v == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return central(current).mu4 / (v * v);
}

double Na4Ensemble::push(std::span<const double> record) {
  add(record);
  return value(record);
}

}  // namespace detect
