#include "opt/throw_search.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_common.h"

namespace kf {

double radical_inverse(int k, int b) {
  double f = 1, r = 0;
  for (; k > 0; k /= b) {
    f /= b;
    r += f * (k % b);
  }
  return r;
}

double large_flight_share(int particles, int steps) {
  const double per_flight = std::max(1.0, double(particles) * std::max(1, steps));
  return std::min(1.0, kLargeFlight / per_flight);
}

int automatic_throw_count(int particles, int steps) {
  const double per_throw = std::max(1.0, double(particles) * std::max(1, steps));
  // A large sheet's evaluations are dear too: beyond kLargeFlight particle-steps a flight, the search's share
  // of the run falls as the square of the flight's cost.
  const double share = large_flight_share(particles, steps);
  const double large = share * share;
  return int(std::clamp(4e6 / per_throw * large, 32.0, 512.0));
}

// Whether the problem's last flight puts every keyframe within half its tolerance (none placed, or one that
// places no particles: never).
class MeetsKeyframes {
 public:
  MeetsKeyframes(Problem& problem, const Scene* scene) {
    if (!scene || !scene->cloth) return;
    bool all = false;
    placed_ = placed_keyframes(problem, *scene, &all);
    if (!all) placed_.clear();
    r_.resize(residual_count(placed_));
    reach_ = 0.5 * cloth_tolerance(*scene);
  }
  bool operator()(const Problem& problem) {
    return !placed_.empty() && !problem.last_diverged() && keyframe_residuals(problem.rollout(), placed_, false, r_) <= reach_;
  }

 private:
  std::vector<PlacedKeyframe> placed_;
  VecX r_;
  double reach_ = 0;
};

namespace {

// The kFitStarts lowest-φ throws offered, kept in fixed storage: the search offers every throw it flies.
class BestThrows {
 public:
  BestThrows() {
    for (VecX& z : z_) z = VecX::Zero(6);
    phi_.fill(INFINITY);
  }
  void offer(double phi, const VecX& z) {
    int k = n_ < kFitStarts ? n_++ : kFitStarts - 1;  // the slot it may take: a free one, or the worst
    if (!(phi < phi_[size_t(k)])) return;
    for (; k > 0 && phi < phi_[size_t(k - 1)]; --k) {
      phi_[size_t(k)] = phi_[size_t(k - 1)];
      z_[size_t(k)] = z_[size_t(k - 1)];
    }
    phi_[size_t(k)] = phi;
    z_[size_t(k)] = z;
  }
  std::vector<VecX> sorted() const {
    std::vector<VecX> out;
    for (int k = 0; k < n_ && std::isfinite(phi_[size_t(k)]); ++k) out.push_back(z_[size_t(k)]);
    return out;
  }

 private:
  std::array<double, kFitStarts> phi_;
  std::array<VecX, kFitStarts> z_;
  int n_ = 0;
};

}  // namespace

ThrowSearch search_throws(Problem& problem, int count, const FittedThrow& fitted, const std::atomic<bool>* stop,
                          const Scene* scene) {
  if (problem.controls().kind() != ControlKind::kInitialRigidVelocity)
    throw std::logic_error("search_throws: the problem's controls are not a rigid throw");
  VecX x0, v0;
  problem.system().initial_state(x0, v0);
  const int p = problem.system().particles();
  Vec3 centre = Vec3::Zero(), mean_v = Vec3::Zero();
  for (int i = 0; i < p; ++i) {
    centre += x0.segment<3>(3 * i);
    mean_v += v0.segment<3>(3 * i);
  }
  centre /= std::max(1, p);
  mean_v /= std::max(1, p);
  double r2 = 0;
  for (int i = 0; i < p; ++i) r2 += (x0.segment<3>(3 * i) - centre).squaredNorm();
  const double radius = std::sqrt(r2 / std::max(1, p));
  MeetsKeyframes meets(problem, scene);
  BestThrows best;

  ThrowSearch s;
  s.speed = std::max(1.0, 0.5 * mean_v.norm());
  s.spin = radius > 0 ? s.speed / radius : 0.0;
  s.z = VecX::Zero(6);
  s.start_phi = s.phi = problem.evaluate(s.z, nullptr);
  if (problem.last_diverged()) s.phi = INFINITY;
  s.fitted = fitted.flown;
  if (fitted.z && fitted.phi < s.phi) s.phi = fitted.phi, s.z = *fitted.z;
  s.simulated += fitted.simulated;
  // Four rounds of a quarter of the throws each: the throw's velocity alone, its spin kept (a spinning sheet
  // rarely lands where a flat one would), then velocity and spin together in boxes half, a quarter and an
  // eighth as wide around the best so far.
  constexpr int kPrimes[6] = {2, 3, 5, 7, 11, 13};
  constexpr int kRounds = 4;
  VecX z(6);
  for (int round = 0; round < kRounds; ++round) {
    const VecX centre_z = s.z;
    const double shrink = round == 0 ? 1.0 : std::ldexp(1.0, -round);
    const int n = count / kRounds + (round < count % kRounds);
    for (int k = 1; k <= n && !(stop && stop->load()); ++k) {
      for (int d = 0; d < 6; ++d) {
        const double half = shrink * (d < 3 ? s.speed : s.spin);
        z[d] = centre_z[d] + (d < 3 || round > 0 ? (2 * radical_inverse(k, kPrimes[d]) - 1) * half : 0.0);
      }
      const double phi = problem.evaluate(z, nullptr);
      ++s.simulated;
      if (!problem.last_diverged()) best.offer(phi, z);
      if (!problem.last_diverged() && phi < s.phi) {
        s.phi = phi;
        s.z = z;
        if (meets(problem)) {  // the rigid stage starts at the keyframes: no throw left to beat it
          s.met = true;
          s.best_throws = best.sorted();
          return s;
        }
      }
    }
  }
  s.best_throws = best.sorted();
  return s;
}

ThrowSearch search_and_fit_throws(Problem& problem, const Scene& scene, int count, int budget,
                                  const std::atomic<bool>* stop) {
  constexpr int kThrowCorrections = 3;  // four flights, a small share of the search
  constexpr int kFirstFit = 100;        // flights for the fit from the scene's and the fitted throw: a few Jacobians
  const FittedThrow fitted = refine_fitted_throw(problem, scene, kThrowCorrections);
  RigidFitOptions o;
  o.stop = stop;
  // Each fit flies at most a quarter of the search's throws: `count` is what a large sheet's time allows.
  const int quarter = std::max(1, count / 4);
  o.max_simulations = std::clamp(budget - fitted.simulated, 0, std::min(kFirstFit, quarter));
  std::vector<VecX> starts = {VecX::Zero(6)};
  if (fitted.z && *fitted.z != starts[0]) starts.push_back(*fitted.z);
  RigidThrowFit rigid = fit_rigid_throw(problem, scene, starts, o);
  // A throw the fit brought within half of every tolerance (the search's own early end) needs no search, and no
  // other start: the rigid stage judges it met (the scene's throw is still flown, once).
  constexpr double kMet = 0.5;
  const bool met = rigid.reached() || (rigid.z.size() == 6 && rigid.worst_miss <= kMet);
  const int spent = fitted.simulated + rigid.simulated;
  const int searched = met ? 0 : std::max(0, std::min(count - rigid.simulated, budget - spent));
  ThrowSearch s = search_throws(problem, searched, fitted, stop, &scene);
  s.simulated += rigid.simulated;
  if (!met && !s.met) {
    const auto fitted_from = [&](const VecX& z) {
      return std::any_of(starts.begin(), starts.end(), [&](const VecX& a) { return a == z; });
    };
    std::vector<VecX> more_starts;
    if (large_flight_share(problem.system().particles(), problem.time().steps()) < 1) {
      if (s.z.size() == 6 && !fitted_from(s.z)) more_starts.push_back(s.z);
    } else {
      for (const VecX& z : s.best_throws)
        if (!fitted_from(z)) more_starts.push_back(z);
    }
    if (more_starts.size() > 1) o.reach_share = kMet;
    for (size_t k = 0; k < more_starts.size(); ++k) {
      // The search's best, when it beats the scene's and the fitted throw, keeps its quarter; the others share
      // what is left evenly.
      const int left = budget - s.simulated;
      o.max_simulations = std::clamp(k == 0 && more_starts[0] == s.z ? left : left / int(more_starts.size() - k), 0, quarter);
      if (o.max_simulations == 0) break;
      const RigidThrowFit more = fit_rigid_throw(problem, scene, {more_starts[k]}, o);
      s.simulated += more.simulated;
      absorb(rigid, more);
      if (more.reached() || (more.z.size() == 6 && more.worst_miss <= kMet)) break;
    }
  }
  if (rigid.z.size() == 6) {
    const double phi = problem.evaluate(rigid.z, nullptr);
    ++s.simulated;
    if (!problem.last_diverged() && phi < s.phi) s.phi = phi, s.z = rigid.z;
  }
  s.rigid = rigid;
  return s;
}

}  // namespace kf
