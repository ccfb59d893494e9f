#include "adjoint/rollout.h"

namespace kf {

bool simulate(System& sys, const VecX& x0, const VecX& v0, const std::vector<VecX>& U, Rollout& r) {
  const int N = int(U.size());
  r.x.resize(N + 1);
  r.v.resize(N + 1);
  r.x[0] = x0;
  r.v[0] = v0;
  r.diverged_at = -1;
  for (int n = 0; n < N; ++n) {
    // Sized once; later rollouts reuse the storage.
    if (r.x[n + 1].size() != x0.size()) r.x[n + 1].resize(x0.size());
    if (r.v[n + 1].size() != x0.size()) r.v[n + 1].resize(x0.size());
    if (!sys.step(n, r.x[n], r.v[n], U[n], r.x[n + 1], r.v[n + 1])) {
      r.diverged_at = n;
      return false;
    }
  }
  return true;
}

double cost_value(const StateCost& cost, const Rollout& r) {
  double phi = 0;
  const int dof = int(r.x[0].size());
  VecX gx = VecX::Zero(dof), gv = VecX::Zero(dof);
  for (int n = 0; n <= r.steps(); ++n)
    if (cost.active(n)) phi += cost.eval(n, r.x[n], r.v[n], gx, gv);
  return phi;
}

void backward(System& sys, const Rollout& r, const std::vector<VecX>& U, const StateCost& cost,
              std::vector<VecX>& dU, VecX& dx0, VecX& dv0) {
  const int N = r.steps(), dof = int(r.x[0].size());
  dU.resize(N);
  VecX xhat = VecX::Zero(dof), vhat = VecX::Zero(dof), xhat_prev(dof), vhat_prev(dof);
  if (cost.active(N)) cost.eval(N, r.x[N], r.v[N], xhat, vhat);
  for (int n = N - 1; n >= 0; --n) {
    dU[n].resize(dof);
    sys.step_adjoint(n, r.x[n], r.v[n], U[n], xhat, vhat, xhat_prev, vhat_prev, dU[n]);
    xhat.swap(xhat_prev);
    vhat.swap(vhat_prev);
    if (cost.active(n)) cost.eval(n, r.x[n], r.v[n], xhat, vhat);
  }
  dx0 = xhat;
  dv0 = vhat;
}

}  // namespace kf
