#pragma once
// A small explicit particle system for testing the optimisation layer on its own: particles joined in a
// chain by linear springs with drag. Its step "diverges" (returns false) when a control force exceeds a limit,
// so the optimiser's recovery from a blown-up trial step can be tested; with `limit_is_unstable` it says the
// step was refused as unstable (divergence_reason), as a flock packed past its step's limit does.
#include "sim/system.h"

namespace kf::test {

class ToySystem : public System {
 public:
  ToySystem(int p, double h, double control_limit = 1e300, bool limit_is_unstable = false)
      : p_(p), h_(h), limit_(control_limit), limit_is_unstable_(limit_is_unstable), m_(VecX::Constant(p, 1.5)) {}
  int particles() const override { return p_; }
  double h() const override { return h_; }
  const VecX& masses() const override { return m_; }
  void initial_state(VecX& x, VecX& v) const override {
    x = VecX::Zero(3 * p_);
    v = VecX::Zero(3 * p_);
    for (int i = 0; i < p_; ++i) x.segment<3>(3 * i) = Vec3(i, 0.1 * i * i, -0.2 * i);
    v[0] = 0.3;
  }
  // f = -k (x_i - x_{i+1}) chain springs, -c v drag.
  void force(const VecX& x, const VecX& v, VecX& f) const {
    f = -c_ * v;
    for (int i = 0; i + 1 < p_; ++i) {
      const Vec3 d = x.segment<3>(3 * i) - x.segment<3>(3 * i + 3) - Vec3(1, 0, 0);
      f.segment<3>(3 * i) -= k_ * d;
      f.segment<3>(3 * i + 3) += k_ * d;
    }
  }
  using System::step;
  using System::step_adjoint;
  bool step(int, const VecX& x, const VecX& v, const VecX& u, VecX& x1, VecX& v1, StepRecord&) override {
    force(x, v, f_);
    for (int i = 0; i < p_; ++i) v1.segment<3>(3 * i) = v.segment<3>(3 * i) + h_ / m_[i] * (f_.segment<3>(3 * i) + u.segment<3>(3 * i));
    x1 = x + h_ * v1;
    refused_ = !(u.cwiseAbs().maxCoeff() < limit_);
    return v1.allFinite() && !refused_;
  }
  std::string divergence_reason() const override {
    return limit_is_unstable_ && refused_ ? "a control force past the toy's limit" : "";
  }
  void step_adjoint(int, const VecX&, const VecX&, const VecX&, const StepRecord&, const VecX& xhat1,
                    const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) override {
    VecX s = vhat1 + h_ * xhat1;
    VecX ms(3 * p_);
    for (int i = 0; i < p_; ++i) ms.segment<3>(3 * i) = s.segment<3>(3 * i) / m_[i];
    // K is symmetric (linear springs), D = -c I.
    VecX kt = VecX::Zero(3 * p_);
    for (int i = 0; i + 1 < p_; ++i) {
      const Vec3 d = ms.segment<3>(3 * i) - ms.segment<3>(3 * i + 3);
      kt.segment<3>(3 * i) -= k_ * d;
      kt.segment<3>(3 * i + 3) += k_ * d;
    }
    xhat = xhat1 + h_ * kt;
    vhat = s - h_ * c_ * ms;
    uhat = h_ * ms;
  }
  std::string describe() const override { return "toy chain"; }

 private:
  int p_;
  double h_, limit_, k_ = 4.0, c_ = 0.3;
  bool limit_is_unstable_, refused_ = false;
  VecX m_;
  mutable VecX f_;
};

}  // namespace kf::test
