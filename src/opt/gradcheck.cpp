#include "opt/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace kf {

nlohmann::json GradcheckResult::to_json() const {
  return {{"checked", checked},     {"max_rel_error", max_rel_error}, {"cosine", cosine},
          {"rel_error_norm", rel_error_norm}, {"floor", floor},      {"grad_norm", grad_norm},
          {"phi", phi},             {"eps", eps}};
}

GradcheckResult gradcheck(Problem& problem, const VecX& z, int samples, double eps, unsigned seed) {
  GradcheckResult r;
  r.eps = eps;
  VecX g(z.size());
  r.phi = problem.evaluate(z, &g);
  r.grad_norm = g.norm();
  // Half the sample from the largest adjoint components, half uniformly at random.
  std::vector<int> order(z.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed);
  std::vector<int> picks;
  const int n_top = std::min<int>(samples / 2, int(z.size()));
  std::partial_sort(order.begin(), order.begin() + n_top, order.end(),
                    [&](int a, int b) { return std::abs(g[a]) > std::abs(g[b]); });
  picks.assign(order.begin(), order.begin() + n_top);
  std::uniform_int_distribution<int> pick(0, int(z.size()) - 1);
  for (int tries = 0; int(picks.size()) < std::min<int>(samples, int(z.size())) && tries < 100 * samples; ++tries) {
    int k = pick(rng);
    if (std::find(picks.begin(), picks.end(), k) == picks.end()) picks.push_back(k);
  }
  std::sort(picks.begin(), picks.end());
  VecX a(picks.size()), fd(picks.size());
  VecX zp = z;
  // Richardson-extrapolated central differences: (4 D(h/2) - D(h)) / 3 cancels the h^2 error term, so
  // a step large enough to keep round-off on a large φ small still leaves an O(h^4) truncation error.
  auto central = [&](int k, double step) {
    zp[k] = z[k] + step;
    const double fp = problem.evaluate(zp, nullptr);
    zp[k] = z[k] - step;
    const double fm = problem.evaluate(zp, nullptr);
    zp[k] = z[k];
    return (fp - fm) / (2 * step);
  };
  for (size_t s = 0; s < picks.size(); ++s) {
    const int k = picks[s];
    const double step = eps * std::max(1.0, std::abs(z[k]));
    fd[s] = (4 * central(k, step / 2) - central(k, step)) / 3;
    a[s] = g[k];
  }
  r.checked = int(picks.size());
  r.floor = 1e-3 * fd.cwiseAbs().maxCoeff();
  for (int s = 0; s < r.checked; ++s)
    r.max_rel_error = std::max(r.max_rel_error, std::abs(a[s] - fd[s]) / std::max(std::abs(fd[s]), r.floor));
  const double na = a.norm(), nf = fd.norm();
  r.cosine = (na > 0 && nf > 0) ? a.dot(fd) / (na * nf) : 0.0;
  r.rel_error_norm = nf > 0 ? (a - fd).norm() / nf : 0.0;
  return r;
}

}  // namespace kf
