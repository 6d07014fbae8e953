#include "sim/validation/heat_reference.h"

#include <cmath>
#include <initializer_list>
#include <numbers>
#include <string>
#include <utility>

#include "sim/error.h"

namespace thaw {

namespace {

constexpr double kSqrtPi = 1.7724538509055160273;

// exp(-z^2) / erfc(z), the far region's flux factor; grows like z sqrt(pi) instead of overflowing.
double inverse_erfcx(double z) { return 1.0 / erfcx(z); }

// erfc(a) / erfc(b) for a >= b >= 0 without 0/0 once both underflow.
double erfc_ratio(double a, double b) { return erfcx(a) / erfcx(b) * std::exp((b - a) * (b + a)); }

void require_positive(double value, const std::string& what) {
  if (!(value > 0) || !std::isfinite(value))
    throw Error("Neumann-Stefan reference: " + what + " must be positive and finite, got " +
                std::to_string(value));
}

}  // namespace

double erfcx(double z) {
  // Below 8 the product loses at most ~z^2 ulp to the rounding of z^2 (< 1e-14). Above, the asymptotic
  // series erfcx(z) = 1/(z sqrt(pi)) sum_k (-1)^k (2k-1)!! / (2 z^2)^k has its smallest term below 1e-27,
  // so summing until the terms fall under round-off is exact to double precision.
  if (z < 8.0) return std::exp(z * z) * std::erfc(z);
  const double x = 1.0 / (2.0 * z * z);
  double term = 1.0, sum = 1.0;
  for (int k = 1; k < 60 && std::abs(term) > 1e-18; ++k) {
    term *= -(2.0 * k - 1.0) * x;
    sum += term;
  }
  return sum / (z * kSqrtPi);
}

double NeumannStefan::nu() const { return std::sqrt(near.diffusivity() / far.diffusivity()); }

double NeumannStefan::front(double t) const {
  return t > 0 ? 2.0 * lambda * std::sqrt(near.diffusivity() * t) : 0.0;
}

// Carslaw & Jaeger section 11.2: each region is an erf/erfc similarity profile of x / (2 sqrt(alpha t)),
// pinned to T_w at the wall, T_m at the front and T_0 at infinity. Written with signed differences, the
// same expressions hold for melting and freezing.
double NeumannStefan::temperature(double x, double t) const {
  if (t <= 0) return initial_temperature;
  if (x < front(t)) {
    const double eta = x / (2.0 * std::sqrt(near.diffusivity() * t));
    return wall_temperature + (melt_temperature - wall_temperature) * std::erf(eta) / std::erf(lambda);
  }
  const double eta = x / (2.0 * std::sqrt(far.diffusivity() * t));
  return initial_temperature + (melt_temperature - initial_temperature) * erfc_ratio(eta, nu() * lambda);
}

// -k dT/dx at x = 0 is k (T_w - T_m) / (erf(lambda) sqrt(pi alpha t)); its time integral doubles sqrt(t).
double NeumannStefan::wall_heat(double t) const {
  if (t <= 0) return 0.0;
  return 2.0 * near.conductivity * (wall_temperature - melt_temperature) * std::sqrt(t) /
         (std::erf(lambda) * std::sqrt(std::numbers::pi * near.diffusivity()));
}

// Enthalpy per volume relative to the far phase at T_m: near rho_n c_n (T - T_m) +- rho_n L, far
// rho_f c_f (T - T_m). Integrated in closed form with int_0^l erf = l erf l - (1 - exp(-l^2)) / sqrt(pi)
// and int_b^inf erfc = exp(-b^2) / sqrt(pi) - b erfc b.
double NeumannStefan::stored_heat(double t) const {
  if (t <= 0) return 0.0;
  const double a_near = 2.0 * std::sqrt(near.diffusivity() * t),
               a_far = 2.0 * std::sqrt(far.diffusivity() * t);
  const double s = lambda * a_near, b = nu() * lambda;
  const double near_excess =  // integral over (0, s) of T - T_m
      (wall_temperature - melt_temperature) * a_near * -std::expm1(-lambda * lambda) /
      (kSqrtPi * std::erf(lambda));
  const double far_excess =  // integral over (s, inf) of T - T_0
      (melt_temperature - initial_temperature) * a_far * (1.0 / (kSqrtPi * erfcx(b)) - b);
  const double latent = (freezing() ? -1.0 : 1.0) * near.density * latent_heat * s;
  const double rho_c_near = near.density * near.specific_heat, rho_c_far = far.density * far.specific_heat;
  return rho_c_near * near_excess + latent + rho_c_far * (melt_temperature - initial_temperature) * s +
         rho_c_far * far_excess;
}

NeumannStefan solve_neumann_stefan(ThermalPhase near, ThermalPhase far, double wall_temperature,
                                   double initial_temperature, double melt_temperature, double latent_heat) {
  for (const auto& [phase, name] : {std::pair{near, "near"}, std::pair{far, "far"}}) {
    require_positive(phase.conductivity, std::string(name) + " phase conductivity");
    require_positive(phase.specific_heat, std::string(name) + " phase specific heat");
    require_positive(phase.density, std::string(name) + " phase density");
  }
  require_positive(latent_heat, "latent heat");
  if (!std::isfinite(wall_temperature) || !std::isfinite(initial_temperature) ||
      !std::isfinite(melt_temperature))
    throw Error("Neumann-Stefan reference: temperatures must be finite");
  const bool melting = wall_temperature > melt_temperature && initial_temperature <= melt_temperature;
  const bool freezing = wall_temperature < melt_temperature && initial_temperature >= melt_temperature;
  if (!melting && !freezing)
    throw Error("Neumann-Stefan reference: wall " + std::to_string(wall_temperature) + ", initial " +
                std::to_string(initial_temperature) + ", melt " + std::to_string(melt_temperature) +
                " describe neither melting (wall > melt >= initial) nor freezing (wall < melt <= initial)");

  NeumannStefan n{near, far, wall_temperature, initial_temperature, melt_temperature, latent_heat, 0.0};
  // Both cases give the Stefan condition rho_n L ds/dt = (heat conducted to the front through the near
  // phase) - (heat conducted away into the far phase) once temperatures enter as magnitudes; the far
  // term's density ratio is 1 in docs/VALIDATION-RESULTS.md's equal-density case.
  const double st_near = near.specific_heat * std::abs(wall_temperature - melt_temperature) / latent_heat;
  const double st_far = far.density * far.specific_heat * std::abs(melt_temperature - initial_temperature) /
                        (near.density * latent_heat);
  const double nu = n.nu();
  // Strictly decreasing in l: +inf at 0+ (St_n > 0), -inf as l grows, so the root is unique.
  const auto residual = [&](double l) {
    return st_near * std::exp(-l * l) / std::erf(l) - st_far * inverse_erfcx(nu * l) / nu - l * kSqrtPi;
  };
  double lo = 1.0, hi = 1.0;
  for (int i = 0; i < 2000 && residual(hi) > 0; ++i) hi *= 2.0;
  for (int i = 0; i < 2000 && residual(lo) < 0; ++i) lo *= 0.5;
  if (!(residual(lo) >= 0 && residual(hi) <= 0))
    throw Error("Neumann-Stefan reference: no root bracketed for St_near " + std::to_string(st_near) +
                ", St_far " + std::to_string(st_far));
  if (lo == hi) lo = hi * 0.5;
  // Bisection to adjacent doubles: ~60 halvings of a factor-2 bracket, robust where Newton is not.
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (residual(mid) > 0 ? lo : hi) = mid;
  }
  n.lambda = 0.5 * (lo + hi);
  return n;
}

double GaussianPulse::variance(double t) const { return sigma0 * sigma0 + 2.0 * diffusivity * t; }

double GaussianPulse::temperature(double r2, double t) const {
  const double v = variance(t);
  return background + amplitude * std::pow(sigma0 * sigma0 / v, 0.5 * dimensions) * std::exp(-r2 / (2.0 * v));
}

namespace {
double radius2(const Float4& x) { return double(x[0]) * x[0] + double(x[1]) * x[1] + double(x[2]) * x[2]; }
}  // namespace

double GaussianPulse::second_moment(const std::vector<Float4>& x, const std::vector<double>& value) const {
  double m0 = 0, m2 = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double e = value[i] - background;
    m0 += e;
    m2 += e * radius2(x[i]);
  }
  return m2 / m0;
}

double GaussianPulse::l2_error(const std::vector<Float4>& x, const std::vector<double>& value,
                               double t) const {
  double err2 = 0, ref2 = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double exact = temperature(radius2(x[i]), t);
    err2 += (value[i] - exact) * (value[i] - exact);
    ref2 += (exact - background) * (exact - background);
  }
  return std::sqrt(err2 / ref2);
}

double GaussianPulse::excess_heat() const {
  return amplitude * std::pow(2.0 * std::numbers::pi * sigma0 * sigma0, 0.5 * dimensions);
}

}  // namespace thaw
