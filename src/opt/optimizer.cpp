#include "opt/optimizer.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <nlopt.hpp>

namespace kf {

namespace {

struct Driver {
  Problem& problem;
  const std::function<void(const EvaluationRecord&)>& on_eval;
  const std::atomic<bool>* stop;
  EvaluationTape* tape;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  OptimizeResult result;
  VecX z, g;

  int max_evaluations = 0;  // a hard limit (NLopt's own maxeval may run past it); 0: none
  bool limit_reached = false;

  double operator()(const std::vector<double>& x, std::vector<double>& grad) {
    if (stop && stop->load()) {
      result.interrupted = true;
      throw nlopt::forced_stop();
    }
    if (max_evaluations > 0 && result.evaluations >= max_evaluations) {
      limit_reached = true;
      throw nlopt::forced_stop();
    }
    z = Eigen::Map<const VecX>(x.data(), Eigen::Index(x.size()));
    g.resize(z.size());
    EvaluationRecord rec;
    const RecordedEvaluation* replayed = tape && !grad.empty() ? tape->replay(z) : nullptr;
    double phi;
    if (replayed) {
      phi = replayed->phi;
      g = replayed->g;
      rec.diverged = replayed->diverged;
      rec.terms = replayed->terms;
      rec.seconds = replayed->seconds;
      // Later evaluations count their seconds on from the recorded ones.
      start = std::chrono::steady_clock::now() - std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                     std::chrono::duration<double>(replayed->seconds));
    } else {
      phi = problem.evaluate(z, grad.empty() ? nullptr : &g);
      rec.diverged = problem.last_diverged();
      rec.terms = problem.breakdown();
      rec.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    if (!grad.empty()) Eigen::Map<VecX>(grad.data(), g.size()) = g;
    if (tape && !grad.empty()) tape->record({z, g, phi, rec.seconds, rec.diverged, rec.terms});
    rec.evaluation = ++result.evaluations;
    rec.phi = phi;
    rec.grad_norm = grad.empty() ? 0 : g.norm();
    if (!rec.diverged && phi < result.phi) {
      result.phi = phi;
      result.z = z;
    }
    if (on_eval) on_eval(rec);
    result.history.push_back(std::move(rec));
    return phi;
  }

  static double thunk(const std::vector<double>& x, std::vector<double>& grad, void* self) {
    return (*static_cast<Driver*>(self))(x, grad);
  }
};

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

}  // namespace

OptimizeResult minimize(Problem& problem, const OptimizerSpec& spec, const VecX& z0,
                        const std::function<void(const EvaluationRecord&)>& on_eval,
                        const std::atomic<bool>* stop, EvaluationTape* tape) {
  Driver d{problem, on_eval, stop, tape};
  d.result.phi = std::numeric_limits<double>::infinity();
  d.result.z = z0;
  const unsigned n = unsigned(z0.size());
  std::vector<double> x(z0.data(), z0.data() + n);
  if (spec.max_evaluations == 0 || n == 0) {
    std::vector<double> g(n);
    d(x, g);
    d.result.status = "no optimisation requested";
  } else {
    nlopt::opt opt(nlopt::LD_LBFGS, n);
    opt.set_min_objective(&Driver::thunk, &d);
    opt.set_maxeval(spec.max_evaluations);
    d.max_evaluations = spec.max_evaluations;
    if (spec.ftol_rel > 0) opt.set_ftol_rel(spec.ftol_rel);
    if (spec.max_seconds > 0) opt.set_maxtime(spec.max_seconds);
    opt.set_vector_storage(unsigned(spec.memory));
    double f = 0;
    try {
      d.result.status = status_name(opt.optimize(x, f));
    } catch (const nlopt::forced_stop&) {
      d.result.status = "interrupted";
    } catch (const nlopt::roundoff_limited&) {
      d.result.status = "converged (limited by round-off)";
    } catch (const std::runtime_error& e) {
      // LBFGS gives up this way when the line search cannot make progress; the best point stands.
      d.result.status = std::string("stopped: line search made no progress (") + e.what() + ")";
    }
    // NLopt may report a forced stop as a generic failure; what stopped it is known here.
    if (d.result.interrupted) d.result.status = "interrupted";
    else if (d.limit_reached) d.result.status = status_name(nlopt::MAXEVAL_REACHED);
  }
  d.result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - d.start).count();
  if (!std::isfinite(d.result.phi)) d.result.phi = problem.evaluate(d.result.z, nullptr);
  return d.result;
}

}  // namespace kf
