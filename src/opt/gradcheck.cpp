#include "opt/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <limits>
#include <random>

namespace kf {

nlohmann::json GradcheckResult::to_json() const {
  nlohmann::json j = {{"checked", checked},     {"kinks", kinks},         {"max_rel_error", max_rel_error},
                      {"cosine", cosine},       {"rel_error_norm", rel_error_norm}, {"fd_spread", fd_spread},
                      {"floor", floor},         {"grad_norm", grad_norm}, {"phi", phi},
                      {"eps", eps}, {"phi_noise", phi_noise}};
  if (diverged) {
    for (const char* k : {"max_rel_error", "cosine", "rel_error_norm", "fd_spread", "floor", "grad_norm", "phi_noise"})
      j[k] = nullptr;
    j["diverged"] = true;
    j["diverged_at_step"] = diverged_at;
  }
  return j;
}

namespace {

std::vector<int> pick_coordinates(const VecX& g, int samples, unsigned seed) {
  const int n = int(g.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  const int n_top = std::min(samples / 2, n);
  std::partial_sort(order.begin(), order.begin() + n_top, order.end(),
                    [&](int a, int b) { return std::abs(g[a]) > std::abs(g[b]); });
  std::vector<int> picks(order.begin(), order.begin() + n_top);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int tries = 0; int(picks.size()) < std::min(samples, n) && tries < 100 * samples; ++tries) {
    const int k = pick(rng);
    if (std::find(picks.begin(), picks.end(), k) == picks.end()) picks.push_back(k);
  }
  std::sort(picks.begin(), picks.end());
  return picks;
}

}  // namespace

double phi_noise(Problem& problem, const VecX& z, double phi, unsigned seed) {
  std::mt19937_64 rng(seed + 1);
  std::normal_distribution<double> normal;
  VecX dir(z.size());
  for (int i = 0; i < z.size(); ++i) dir[i] = normal(rng);
  const double delta = 1e-9 * std::max(1.0, z.cwiseAbs().maxCoeff()) / std::max(dir.norm(), 1e-300);
  double f[7];
  for (int j = -3; j <= 3; ++j) f[j + 3] = j == 0 ? phi : problem.evaluate(VecX(z + j * delta * dir), nullptr);
  double sum = 0;
  for (int j = 1; j < 6; ++j) sum += std::pow(f[j + 1] - 2 * f[j] + f[j - 1], 2);
  // At least φ's own rounding: a φ that is linear to the last bit there still quantises differences.
  return std::max(std::sqrt(sum / 5 / 6), std::numeric_limits<double>::epsilon() * std::abs(phi));
}

DifferenceEstimate extrapolated_difference(double step, const std::function<double(double)>& central,
                                           double target, double noise) {
  constexpr int kLevels = 16;  // down to step / 2^15
  constexpr int kNoisy = 3;    // levels in a row whose change round-off explains: smaller steps only lose
  DifferenceEstimate best{0, std::numeric_limits<double>::infinity()};
  double h = step, d_prev = central(h), r_prev = 0;
  int noisy = 0;
  for (int i = 1; i < kLevels; ++i) {
    h /= 2;
    const double d = central(h);
    const double r = (4 * d - d_prev) / 3;  // Richardson: the pair's O(h²) error cancels
    if (i >= 2) {
      // Three times the change: a sequence growing like 1/h (a jump of φ) is twice its last change away
      // from where it started. r's round-off is about noise / h.
      const double change = std::abs(r - r_prev), error = 3 * change + 3 * noise / h;
      if (error < best.error) best = {r, error};
      if (best.error <= target * std::abs(best.value)) break;
      noisy = change <= 10 * noise / h ? noisy + 1 : 0;
      if (noisy == kNoisy) break;
    }
    d_prev = d;
    r_prev = r;
  }
  return best;
}

GradcheckResult gradcheck(Problem& problem, const VecX& z, const GradcheckOptions& o) {
  constexpr double kResolution = 1e-9;  // a relative error estimate at which a sample needs no smaller steps
  GradcheckResult r;
  r.eps = o.eps;
  VecX g(z.size());
  r.phi = problem.evaluate(z, &g);
  if (problem.last_diverged()) {
    r.diverged = true;
    r.diverged_at = problem.rollout().diverged_at;
    return r;
  }
  r.grad_norm = g.norm();
  const std::vector<int> picks = pick_coordinates(g, o.samples, o.seed);
  r.phi_noise = phi_noise(problem, z, r.phi, o.seed);
  VecX zp = z;
  auto central = [&](int k, double step) {
    zp[k] = z[k] + step;
    const double fp = problem.evaluate(zp, nullptr);
    zp[k] = z[k] - step;
    const double fm = problem.evaluate(zp, nullptr);
    zp[k] = z[k];
    return (fp - fm) / (2 * step);
  };
  const int m = int(picks.size());
  VecX spread(m), fd(m);
  for (int s = 0; s < m; ++s) {
    // From 4 eps, so the first extrapolation, of steps 2 eps and eps, is complete at eps: where φ's
    // round-off dominates (small components of a large objective) the larger steps are the better ones.
    const double step = 4 * o.eps * std::max(1.0, std::abs(z[picks[s]]));
    const DifferenceEstimate e =
        extrapolated_difference(step, [&](double h) { return central(picks[s], h); }, kResolution, r.phi_noise);
    fd[s] = e.value;
    spread[s] = e.error / std::max(std::abs(e.value), 1e-300);
  }
  r.floor = m > 0 ? 1e-3 * fd.cwiseAbs().maxCoeff() : 0.0;
  double dot = 0, na = 0, nf = 0, ne = 0;
  for (int s = 0; s < m; ++s) {
    const double scale = std::max(std::abs(fd[s]), r.floor);
    const double sp = spread[s] * std::max({std::abs(fd[s]), 1e-300}) / std::max(scale, 1e-300);
    if (sp > o.kink_tolerance) {
      ++r.kinks;
      continue;
    }
    ++r.checked;
    const double a = g[picks[s]], f = fd[s];
    r.fd_spread = std::max(r.fd_spread, sp);
    r.max_rel_error = std::max(r.max_rel_error, scale > 0 ? std::abs(a - f) / scale : std::abs(a));
    dot += a * f;
    na += a * a;
    nf += f * f;
    ne += (a - f) * (a - f);
  }
  r.cosine = na > 0 && nf > 0 ? dot / std::sqrt(na * nf) : 0.0;
  r.rel_error_norm = nf > 0 ? std::sqrt(ne / nf) : 0.0;
  return r;
}

}  // namespace kf
