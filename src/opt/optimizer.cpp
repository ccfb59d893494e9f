#include "opt/optimizer.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <nlopt.hpp>

namespace kf {

namespace {

struct Driver {
  Driver(Problem& p, const std::function<void(const EvaluationRecord&)>& e, const std::atomic<bool>* s,
         EvaluationTape* t, const std::function<bool()>& r)
      : problem(p), on_eval(e), stop(s), tape(t), reached(r) {}
  Problem& problem;
  const std::function<void(const EvaluationRecord&)>& on_eval;
  const std::atomic<bool>* stop;
  EvaluationTape* tape;
  const std::function<bool()>& reached;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  OptimizeResult result;
  VecX z, g;

  int max_evaluations = 0;  // a hard limit (NLopt's own maxeval may run past it); 0: none
  bool limit_reached = false;
  // NLopt's variables y give the controls z = z0 + scale·y (scale 1: z = y, bit for bit as without it).
  VecX z0;
  double scale = 1;
  // The evaluation at z0 made before NLopt starts, served again when NLopt asks for it first.
  bool have_first = false;
  double first_phi = 0;
  VecX first_g;
  // After a trial the system refused as unstable (a flock packed past what its step can follow), a trial
  // farther than `reach` from the best point is refused as well, without simulating it: L-BFGS's full step
  // keeps asking for such a state, and each would cost most of a forward pass and one of the evaluations.
  // reach is half the refused trial's distance, and doubles when an accepted step comes near it.
  double reach = std::numeric_limits<double>::infinity();

  double operator()(const std::vector<double>& x, std::vector<double>& grad) {
    const Eigen::Map<const VecX> y(x.data(), Eigen::Index(x.size()));
    if (scale == 1) z = y;
    else z = z0 + scale * y;
    if (have_first) {
      have_first = false;
      if (z == z0) {
        if (!grad.empty()) Eigen::Map<VecX>(grad.data(), first_g.size()) = scale * first_g;
        return first_phi;
      }
    }
    double phi;
    if (result.evaluations > 0 && (z - result.z).norm() > reach) {
      ++result.capped_trials;
      phi = problem.refuse(z, grad.empty() ? nullptr : &g);
    } else {
      phi = evaluate(grad.empty() ? nullptr : &g);
    }
    if (!grad.empty()) Eigen::Map<VecX>(grad.data(), g.size()) = scale * g;
    return phi;
  }

  // φ (and dφ/dz into *gz) at z, recorded as one evaluation.
  double evaluate(VecX* gz) {
    // NLopt may call once more after a forced stop before it returns.
    if (result.reached) throw nlopt::forced_stop();
    if (stop && stop->load()) {
      result.interrupted = true;
      throw nlopt::forced_stop();
    }
    if (max_evaluations > 0 && result.evaluations >= max_evaluations) {
      limit_reached = true;
      throw nlopt::forced_stop();
    }
    g.resize(z.size());
    EvaluationRecord rec;
    const RecordedEvaluation* replayed = tape && gz ? tape->replay(z) : nullptr;
    double phi;
    if (replayed) {
      phi = replayed->phi;
      *gz = replayed->g;
      rec.diverged = replayed->diverged;
      rec.unstable = replayed->unstable;
      rec.terms = replayed->terms;
      rec.seconds = replayed->seconds;
      // Later evaluations count their seconds on from the recorded ones.
      start = std::chrono::steady_clock::now() - std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                     std::chrono::duration<double>(replayed->seconds));
    } else {
      phi = problem.evaluate(z, gz);
      rec.diverged = problem.last_diverged();
      rec.unstable = rec.diverged && !problem.system().divergence_reason().empty();
      rec.terms = problem.breakdown();
      rec.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    rec.evaluation = ++result.evaluations;
    rec.phi = phi;
    rec.grad_norm = gz ? gz->norm() : 0;
    const double step = result.evaluations > 1 ? (z - result.z).norm() : 0.0;
    if (rec.unstable) reach = 0.5 * step;
    bool met = false;
    if (!rec.diverged && phi < result.phi) {
      if (step > 0.5 * reach) reach *= 2;
      result.phi = phi;
      result.z = z;
      // A replayed evaluation has no rollout to judge: the stop rule's verdict was recorded with it.
      met = replayed ? replayed->reached : reached && reached();
    }
    if (tape && gz) {
      RecordedEvaluation e{z, *gz, phi, rec.seconds, rec.diverged, rec.unstable, met, rec.terms};
      tape->record(std::move(e));
    }
    if (on_eval) on_eval(rec);
    result.history.push_back(std::move(rec));
    if (met) {
      result.reached = true;
      throw nlopt::forced_stop();
    }
    return phi;
  }

  static double thunk(const std::vector<double>& x, std::vector<double>& grad, void* self) {
    return (*static_cast<Driver*>(self))(x, grad);
  }
};

StopReason stop_reason(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS:
    case nlopt::FTOL_REACHED:
    case nlopt::XTOL_REACHED: return StopReason::kConverged;
    case nlopt::STOPVAL_REACHED: return StopReason::kStopValue;
    case nlopt::MAXEVAL_REACHED: return StopReason::kEvaluationLimit;
    case nlopt::MAXTIME_REACHED: return StopReason::kTimeLimit;
    default: return StopReason::kOther;
  }
}

std::string status_name(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS: return "converged";
    case nlopt::STOPVAL_REACHED: return "objective below stop value";
    case nlopt::FTOL_REACHED: return "converged (relative objective change below ftol_rel)";
    case nlopt::XTOL_REACHED: return "converged (step below tolerance)";
    case nlopt::MAXEVAL_REACHED: return "evaluation limit reached";
    case nlopt::MAXTIME_REACHED: return "time limit reached";
    default: return "stopped (" + std::to_string(int(r)) + ")";
  }
}

void set_stop(OptimizeResult& r, StopReason reason, std::string status) {
  r.reason = reason;
  r.status = std::move(status);
}

// NLopt may report a forced stop as a generic failure; what stopped it is known here. A stop asked for
// during the evaluation NLopt ended on (its line search gave up, or it converged, without asking again)
// is an interruption too: the run stops because it was told to, whatever NLopt said.
void settle_stop(Driver& d, const std::atomic<bool>* stop) {
  if (stop && stop->load()) d.result.interrupted = true;
  if (d.result.interrupted) set_stop(d.result, StopReason::kInterrupted, "interrupted");
  else if (d.result.reached) set_stop(d.result, StopReason::kKeyframesReached, kKeyframesReached);
  else if (d.limit_reached) set_stop(d.result, StopReason::kEvaluationLimit, status_name(nlopt::MAXEVAL_REACHED));
}

}  // namespace

OptimizeResult minimize(Problem& problem, const OptimizerSpec& spec, const VecX& z0,
                        const std::function<void(const EvaluationRecord&)>& on_eval,
                        const std::atomic<bool>* stop, EvaluationTape* tape, const std::function<bool()>& reached) {
  Driver d(problem, on_eval, stop, tape, reached);
  d.result.phi = std::numeric_limits<double>::infinity();
  d.result.z = z0;
  const unsigned n = unsigned(z0.size());
  std::vector<double> x(z0.data(), z0.data() + n);
  if (spec.max_evaluations == 0 || n == 0) {
    std::vector<double> g(n);
    d(x, g);
    set_stop(d.result, StopReason::kNotOptimised, "no optimisation requested");
  } else {
    // NLopt's LD_LBFGS ignores set_initial_step: its first trial step (and the first after each of its
    // internal restarts) is the whole negative gradient, 1e10 on sensitive cloth. Scaling the variables
    // uniformly by s makes that step s² times the gradient while L-BFGS's later steps, scaled by their
    // own curvature estimate, stay as they were; s is chosen so the first trial moves the controls by
    // first_step RMS per variable, and only when the gradient is steeper than that.
    double f = 0;
    try {
      const double rms = spec.first_step > 0 ? spec.first_step : 0;  // automatic (< 0) is resolved by the caller
      if (rms > 0) {
        d.z = z0;
        d.first_phi = d.evaluate(&d.g);
        d.first_g = d.g;
        d.have_first = !d.result.history.back().diverged;  // a replayed evaluation leaves the problem untouched
        d.z0 = z0;
        const double gnorm = d.first_g.norm(), step = rms * std::sqrt(double(n));
        if (d.have_first && std::isfinite(gnorm) && gnorm > step) {
          d.scale = std::sqrt(step / gnorm);
          std::fill(x.begin(), x.end(), 0.0);
        }
      }
      nlopt::opt opt(nlopt::LD_LBFGS, n);
      opt.set_min_objective(&Driver::thunk, &d);
      // Trials refused unsimulated count for NLopt, not for the limit: it stops at the evaluation after it.
      opt.set_maxeval(4 * spec.max_evaluations);
      d.max_evaluations = spec.max_evaluations;
      if (spec.ftol_rel > 0) opt.set_ftol_rel(spec.ftol_rel);
      if (spec.max_seconds > 0) opt.set_maxtime(spec.max_seconds);
      opt.set_vector_storage(unsigned(spec.memory));
      const nlopt::result r = opt.optimize(x, f);
      set_stop(d.result, stop_reason(r), status_name(r));
    } catch (const nlopt::forced_stop&) {
      set_stop(d.result, StopReason::kInterrupted, "interrupted");
    } catch (const nlopt::roundoff_limited&) {
      set_stop(d.result, StopReason::kConverged, "converged (limited by round-off)");
    } catch (const std::runtime_error& e) {
      // LBFGS gives up this way when the line search cannot make progress; the best point stands.
      set_stop(d.result, StopReason::kLineSearchStalled,
               std::string("stopped: line search made no progress (") + e.what() + ")");
    }
    settle_stop(d, stop);
  }
  d.result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - d.start).count();
  if (!std::isfinite(d.result.phi)) d.result.phi = problem.evaluate(d.result.z, nullptr);
  return d.result;
}

}  // namespace kf
