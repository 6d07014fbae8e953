// The exact heat-conduction references: the values the validation specification prints for its cases
// (docs/VALIDATION-RESULTS.md quotes them), the equations they solve, and the conservation laws they obey,
// checked by quadrature that does not share their closed forms.
#include "sim/validation/heat_reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <numbers>
#include <string>

#include "sim/error.h"

namespace thaw {
namespace {

// docs/VALIDATION-RESULTS.md's materials at the equal density the Stefan case uses.
const ThermalPhase kWater{0.56, 4217.0, 1000.0};
const ThermalPhase kIce{2.22, 2050.0, 1000.0};
constexpr double kLatent = 334000.0;

// Composite Simpson; the integrands are smooth on each interval they are used on.
double integrate(const std::function<double(double)>& f, double a, double b, int n = 4000) {
  const double h = (b - a) / n;
  double sum = f(a) + f(b);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return sum * h / 3.0;
}

// Neumann's transcendental equation for the front (docs/VALIDATION-RESULTS.md, Stefan), with std::erf/erfc
// (moderate arguments only).
double stefan_residual(const NeumannStefan& n, double lambda) {
  const double st_near =
      n.near.specific_heat * std::abs(n.wall_temperature - n.melt_temperature) / n.latent_heat;
  const double st_far = n.far.density * n.far.specific_heat *
                        std::abs(n.melt_temperature - n.initial_temperature) /
                        (n.near.density * n.latent_heat);
  const double nu = std::sqrt(n.near.diffusivity() / n.far.diffusivity());
  return st_near / (std::exp(lambda * lambda) * std::erf(lambda)) -
         st_far / (nu * std::exp(nu * nu * lambda * lambda) * std::erfc(nu * lambda)) -
         lambda * std::sqrt(std::numbers::pi);
}

// Enthalpy gained per unit area since t = 0, by quadrature. Per unit volume, a point now in the near
// phase gained rho_n c_n (T - T_m) +- rho_n L (melting / freezing) + rho_f c_f (T_m - T_0): cooled or
// warmed to T_m as far phase, converted, then brought to T as near phase. A far point gained
// rho_f c_f (T - T_0).
double stored_by_quadrature(const NeumannStefan& n, double t) {
  const double s = n.front(t);
  const double sign = n.freezing() ? -1.0 : 1.0;
  const double rc_near = n.near.density * n.near.specific_heat, rc_far = n.far.density * n.far.specific_heat;
  const double near = integrate(
      [&](double x) {
        return rc_near * (n.temperature(x, t) - n.melt_temperature) + sign * n.near.density * n.latent_heat +
               rc_far * (n.melt_temperature - n.initial_temperature);
      },
      0.0, s * (1 - 1e-15));
  // erfc(20) ~ 5e-176: the far field has relaxed to T_0 long before 40 diffusion lengths.
  const double far =
      integrate([&](double x) { return rc_far * (n.temperature(x, t) - n.initial_temperature); }, s,
                s + 40.0 * std::sqrt(n.far.diffusivity() * t));
  return near + far;
}

TEST(HeatReference, NeumannStefanMatchesTheValidationTable) {
  const NeumannStefan one_phase = solve_neumann_stefan(kWater, kIce, 10.0, 0.0, 0.0, kLatent);
  EXPECT_NEAR(one_phase.lambda, 0.246208, 5e-7);
  EXPECT_NEAR(one_phase.front(600.0), 4.395e-3, 5e-7);
  EXPECT_NEAR(one_phase.front(3600.0), 10.767e-3, 5e-7);

  const NeumannStefan two_phase = solve_neumann_stefan(kWater, kIce, 10.0, -10.0, 0.0, kLatent);
  EXPECT_NEAR(two_phase.lambda, 0.200182, 5e-7);
  EXPECT_NEAR(two_phase.front(600.0), 3.574e-3, 5e-7);
  EXPECT_NEAR(two_phase.front(3600.0), 8.754e-3, 5e-7);
  EXPECT_FALSE(two_phase.freezing());
}

TEST(HeatReference, NeumannStefanSolvesItsEquationToRoundOff) {
  for (double wall : {1.0, 10.0, 50.0})
    for (double ice : {0.0, -1.0, -10.0, -40.0}) {
      const NeumannStefan n = solve_neumann_stefan(kWater, kIce, wall, ice, 0.0, kLatent);
      // The residual's slope is O(1), so a root within 1e-14 relative leaves a residual of that order.
      EXPECT_NEAR(stefan_residual(n, n.lambda), 0.0, 1e-13) << wall << " / " << ice;
      // ... and it changes sign across the root: the solver did not stop at a merely small value.
      EXPECT_GT(stefan_residual(n, n.lambda * (1 - 1e-10)), 0.0);
      EXPECT_LT(stefan_residual(n, n.lambda * (1 + 1e-10)), 0.0);
    }
  // Without sub-cooling the far term vanishes: the one-phase equation lambda exp(lambda^2) erf(lambda) =
  // St / sqrt(pi).
  const NeumannStefan n = solve_neumann_stefan(kWater, kIce, 10.0, 0.0, 0.0, kLatent);
  EXPECT_NEAR(n.lambda * std::exp(n.lambda * n.lambda) * std::erf(n.lambda),
              4217.0 * 10.0 / kLatent / std::sqrt(std::numbers::pi), 1e-15);
  // Sub-cooled ice draws heat away from the front, so it melts more slowly.
  EXPECT_LT(solve_neumann_stefan(kWater, kIce, 10.0, -20.0, 0.0, kLatent).lambda,
            solve_neumann_stefan(kWater, kIce, 10.0, -10.0, 0.0, kLatent).lambda);
}

TEST(HeatReference, NeumannStefanTemperatureMeetsItsBoundaryConditions) {
  for (const NeumannStefan& n : {solve_neumann_stefan(kWater, kIce, 10.0, -10.0, 0.0, kLatent),
                                 solve_neumann_stefan(kIce, kWater, -10.0, 5.0, 0.0, kLatent)})
    for (double t : {1.0, 600.0, 3600.0}) {
      const double s = n.front(t);
      EXPECT_NEAR(n.temperature(0.0, t), n.wall_temperature, 1e-12);
      EXPECT_NEAR(n.temperature(s, t), n.melt_temperature, 1e-12);
      EXPECT_NEAR(n.temperature(s * (1 - 1e-12), t), n.melt_temperature, 1e-9) << "continuous at the front";
      EXPECT_NEAR(n.temperature(s * (1 + 1e-12), t), n.melt_temperature, 1e-9);
      EXPECT_NEAR(n.temperature(s + 30.0 * std::sqrt(n.far.diffusivity() * t), t), n.initial_temperature,
                  1e-12);
      // Between wall and front the near phase lies strictly between T_w and T_m.
      const double mid = n.temperature(0.5 * s, t);
      EXPECT_GT(std::abs(mid - n.melt_temperature), 0.0);
      EXPECT_LT(std::abs(mid - n.melt_temperature), std::abs(n.wall_temperature - n.melt_temperature));
    }
}

// Each region obeys T_t = alpha T_xx (central differences, away from the front), and the front obeys the
// Stefan condition rho_n L ds/dt = +-(k_f T_x(s+) - k_n T_x(s-)) (one-sided differences).
TEST(HeatReference, NeumannStefanSolvesTheHeatEquationAndTheStefanCondition) {
  for (const NeumannStefan& n : {solve_neumann_stefan(kWater, kIce, 10.0, -10.0, 0.0, kLatent),
                                 solve_neumann_stefan(kIce, kWater, -10.0, 5.0, 0.0, kLatent)}) {
    const double t = 600.0, s = n.front(t);
    for (double x : {0.3 * s, 0.7 * s, 1.5 * s, 3.0 * s}) {
      const double alpha = x < s ? n.near.diffusivity() : n.far.diffusivity();
      const double dt = 1e-2, dx = 1e-2 * s;
      const double T_t = (n.temperature(x, t + dt) - n.temperature(x, t - dt)) / (2 * dt);
      const double T_xx =
          (n.temperature(x + dx, t) - 2 * n.temperature(x, t) + n.temperature(x - dx, t)) / (dx * dx);
      EXPECT_NEAR(T_t, alpha * T_xx, 1e-4 * std::abs(T_t) + 1e-12) << x / s;
    }
    const double h = 1e-5 * s;  // second-order one-sided differences
    const double Tx_near =
        (3 * n.temperature(s - 1e-15, t) - 4 * n.temperature(s - h, t) + n.temperature(s - 2 * h, t)) /
        (2 * h);
    const double Tx_far =
        (-3 * n.temperature(s, t) + 4 * n.temperature(s + h, t) - n.temperature(s + 2 * h, t)) / (2 * h);
    const double sign = n.freezing() ? -1.0 : 1.0;
    const double latent =
        sign * n.near.density * n.latent_heat * n.lambda * std::sqrt(n.near.diffusivity() / t);
    EXPECT_NEAR(latent, n.far.conductivity * Tx_far - n.near.conductivity * Tx_near, 1e-6 * std::abs(latent));
  }
}

// Heat in through the wall = latent heat of the converted layer + sensible heat of both regions.
TEST(HeatReference, NeumannStefanWallHeatClosesTheEnergyBalance) {
  const ThermalPhase real_ice{2.22, 2050.0, 917.0};
  const NeumannStefan cases[] = {
      solve_neumann_stefan(kWater, kIce, 10.0, 0.0, 0.0, kLatent),
      solve_neumann_stefan(kWater, kIce, 10.0, -10.0, 0.0, kLatent),
      solve_neumann_stefan(kWater, kIce, 3.0, -25.0, 0.0, kLatent),
      solve_neumann_stefan(kWater, real_ice, 10.0, -10.0, 0.0, kLatent),  // conduction-only model
      solve_neumann_stefan(kIce, kWater, -10.0, 5.0, 0.0, kLatent),       // freezing, warm water
      solve_neumann_stefan(kIce, kWater, -10.0, 0.0, 0.0, kLatent),       // freezing, water at T_m
      solve_neumann_stefan(kIce, kWater, 5.0, 20.0, 15.0, 100000.0),      // shifted melt point
  };
  for (const NeumannStefan& n : cases)
    for (double t : {1.0, 600.0, 3600.0}) {
      const double wall = n.wall_heat(t);
      EXPECT_EQ(wall < 0, n.freezing());
      EXPECT_NEAR(stored_by_quadrature(n, t), wall, 1e-6 * std::abs(wall))
          << "wall " << n.wall_temperature << " initial " << n.initial_temperature << " t " << t;
      EXPECT_NEAR(n.stored_heat(t), wall, 1e-12 * std::abs(wall));
      // Flux ~ 1/sqrt(t): the heat taken in grows like sqrt(t).
      EXPECT_NEAR(n.wall_heat(4 * t), 2 * wall, 1e-12 * std::abs(wall));
    }
}

TEST(HeatReference, NeumannStefanFreezingSolvesTheSwappedEquation) {
  for (double water : {0.0, 5.0}) {
    const NeumannStefan n = solve_neumann_stefan(kIce, kWater, -10.0, water, 0.0, kLatent);
    EXPECT_TRUE(n.freezing());
    EXPECT_GT(n.lambda, 0.0);
    EXPECT_NEAR(stefan_residual(n, n.lambda), 0.0, 1e-13);
    EXPECT_LT(n.wall_heat(600.0), 0.0);
    // Ice conducts four times better than water: a -10 wall freezes faster than a +10 wall melts.
    EXPECT_GT(n.front(600.0), solve_neumann_stefan(kWater, kIce, 10.0, -water, 0.0, kLatent).front(600.0));
  }
  // Warm water brings heat to the front that the ice must also carry away.
  EXPECT_LT(solve_neumann_stefan(kIce, kWater, -10.0, 5.0, 0.0, kLatent).lambda,
            solve_neumann_stefan(kIce, kWater, -10.0, 0.0, 0.0, kLatent).lambda);
}

// A far phase that barely conducts puts nu lambda far beyond where erfc underflows (erfc(27) ~ 1e-319).
TEST(HeatReference, NeumannStefanHandlesLargeErfcArguments) {
  const ThermalPhase insulator{1e-7, 2050.0, 1000.0};
  const NeumannStefan n = solve_neumann_stefan(kWater, insulator, 10.0, -10.0, 0.0, kLatent);
  const double b = n.nu() * n.lambda;
  ASSERT_GT(b, 30.0);
  EXPECT_TRUE(std::isfinite(n.lambda));
  // The residual with exp(-b^2)/erfc(b) = 1/erfcx(b) stays at round-off.
  const double st_near = 4217.0 * 10.0 / kLatent, st_far = 2050.0 * 10.0 / kLatent;
  EXPECT_NEAR(st_near / (std::exp(n.lambda * n.lambda) * std::erf(n.lambda)) - st_far / (n.nu() * erfcx(b)) -
                  n.lambda * std::sqrt(std::numbers::pi),
              0.0, 1e-13);
  EXPECT_TRUE(std::isfinite(n.temperature(2 * n.front(600.0), 600.0)));
  EXPECT_NEAR(n.stored_heat(600.0), n.wall_heat(600.0), 1e-9 * std::abs(n.wall_heat(600.0)));
  // erfcx itself: the product form where it is representable, 1/(z sqrt(pi)) far out.
  for (double z : {0.0, 0.5, 3.0, 7.9, 8.0, 8.1, 15.0, 25.0})
    EXPECT_NEAR(erfcx(z), std::exp(z * z) * std::erfc(z), 1e-13 * erfcx(z)) << z;
  for (double z : {1e3, 1e6, 1e100})
    EXPECT_NEAR(erfcx(z) * z * std::sqrt(std::numbers::pi), 1.0, 0.5 / (z * z) + 1e-15) << z;
}

TEST(HeatReference, NeumannStefanRejectsParametersThatDescribeNoPhaseChange) {
  EXPECT_THROW(solve_neumann_stefan(kWater, kIce, 0.0, -10.0, 0.0, kLatent), Error);   // wall at T_m
  EXPECT_THROW(solve_neumann_stefan(kWater, kIce, 10.0, 5.0, 0.0, kLatent), Error);    // all above T_m
  EXPECT_THROW(solve_neumann_stefan(kIce, kWater, -10.0, -5.0, 0.0, kLatent), Error);  // all below T_m
  EXPECT_THROW(solve_neumann_stefan(kWater, kIce, 10.0, -10.0, 0.0, 0.0), Error);      // no latent heat
  EXPECT_THROW(solve_neumann_stefan({-0.56, 4217.0, 1000.0}, kIce, 10.0, -10.0, 0.0, kLatent), Error);
  EXPECT_THROW(solve_neumann_stefan(kWater, {2.22, 2050.0, 0.0}, 10.0, -10.0, 0.0, kLatent), Error);
  EXPECT_THROW(solve_neumann_stefan(kWater, kIce, NAN, -10.0, 0.0, kLatent), Error);
  try {
    solve_neumann_stefan(kWater, kIce, 10.0, 5.0, 0.0, kLatent);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("neither melting"), std::string::npos) << e.what();
  }
}

// Excess heat and second moment by radial quadrature: integral over r of omega_d r^(d-1) (...) dr.
TEST(HeatReference, GaussianPulseConservesHeatAndSpreadsAtTheDiffusivity) {
  for (int d : {1, 2, 3}) {
    const GaussianPulse g{5.0, 2.0, 0.01, 1.3e-7, d};
    const auto shell = [d](double r) {
      return d == 1 ? 2.0 : d == 2 ? 2 * std::numbers::pi * r : 4 * std::numbers::pi * r * r;
    };
    double heat0 = 0;
    for (double t : {0.0, 100.0, 1000.0, 10000.0}) {
      const double R = 15.0 * std::sqrt(g.variance(t));
      const double heat =
          integrate([&](double r) { return shell(r) * (g.temperature(r * r, t) - 5.0); }, 0, R);
      const double moment =
          integrate([&](double r) { return shell(r) * r * r * (g.temperature(r * r, t) - 5.0); }, 0, R);
      if (t == 0) heat0 = heat;
      EXPECT_NEAR(heat, heat0, 1e-10 * heat0) << d << "-D, t " << t;
      EXPECT_NEAR(heat, g.excess_heat(), 1e-10 * heat0) << d << "-D, t " << t;
      EXPECT_NEAR(moment / heat, d * g.variance(t), 1e-10 * d * g.variance(t)) << d << "-D, t " << t;
    }
    EXPECT_DOUBLE_EQ(g.temperature(0.0, 0.0), 7.0);
    EXPECT_DOUBLE_EQ(g.variance(1000.0), 1e-4 + 2 * 1.3e-7 * 1000.0);
    // And it solves T_t = alpha (T_rr + (d - 1) T_r / r) off the centre.
    const double t = 500.0, dt = 1e-1;
    for (double r : {0.005, 0.01, 0.03}) {
      const double dr = 1e-4 * r;
      const auto T = [&](double rr, double tt) { return g.temperature(rr * rr, tt); };
      const double T_t = (T(r, t + dt) - T(r, t - dt)) / (2 * dt);
      const double T_r = (T(r + dr, t) - T(r - dr, t)) / (2 * dr);
      const double T_rr = (T(r + dr, t) - 2 * T(r, t) + T(r - dr, t)) / (dr * dr);
      EXPECT_NEAR(T_t, g.diffusivity * (T_rr + (d - 1) * T_r / r), 1e-4 * std::abs(T_t))
          << d << "-D, r " << r;
    }
  }
}

}  // namespace
}  // namespace thaw
