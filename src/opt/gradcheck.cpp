#include "opt/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace kf {

nlohmann::json GradcheckResult::to_json() const {
  return {{"checked", checked},     {"kinks", kinks},         {"max_rel_error", max_rel_error},
          {"cosine", cosine},       {"rel_error_norm", rel_error_norm}, {"fd_spread", fd_spread},
          {"floor", floor},         {"grad_norm", grad_norm}, {"phi", phi},
          {"eps", eps}};
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

GradcheckResult gradcheck(Problem& problem, const VecX& z, const GradcheckOptions& o) {
  GradcheckResult r;
  r.eps = o.eps;
  VecX g(z.size());
  r.phi = problem.evaluate(z, &g);
  r.grad_norm = g.norm();
  const std::vector<int> picks = pick_coordinates(g, o.samples, o.seed);
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
  // Per sample: differences at eps, eps/10 and eps/100; the adjacent pair that agrees better is used (the
  // larger pair where the finer one drowns in round-off, the finer where φ curves strongly at eps).
  VecX spread(m), fd(m);
  for (int s = 0; s < m; ++s) {
    const double step = o.eps * std::max(1.0, std::abs(z[picks[s]]));
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = central(picks[s], step * std::pow(0.1, k));
    const double scale = std::max({std::abs(d[1]), std::abs(d[2]), 1e-300});
    const double s01 = std::abs(d[0] - d[1]) / scale, s12 = std::abs(d[1] - d[2]) / scale;
    const int c = s12 < s01 ? 1 : 0;  // the pair (c, c+1)
    spread[s] = std::min(s01, s12);
    // Richardson's extrapolation cancels the pair's O(step^2) error.
    fd[s] = d[c + 1] + (d[c + 1] - d[c]) / 99;
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
