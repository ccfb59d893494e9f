#pragma once
// A cape on an animated character (paper figure 6): a Choi-Ko cloth whose top edge follows the skinned
// shoulder anchors, pushed out of the moving body mesh and out of itself, inside the step and its adjoint.
//
// Step n uses the body posed at animation time animation_time(spec, n h fps) and a spatial hash of x_n.
// Backward: the cloth's adjoint with the body and self contacts among its colliders, posed and hashed at
// the same x_n. The swap adjoint also drops the body contact's curvature (BodyCollider::set_curvature).
#include <memory>
#include <vector>

#include "scene/character_spec.h"
#include "scene/cloth_spec.h"
#include "sim/cape/body_collider.h"
#include "sim/cape/self_collider.h"
#include "sim/character/character.h"
#include "sim/cloth/cloth_system.h"

namespace kf {

class CapeSystem final : public System {
 public:
  // cloth: the cape (with anchors, its top edge is pinned to them whatever cloth.pins says; with
  // anchors "none", cloth.pins hold still and a free sheet can fall onto the body); fps: frames per
  // second of the scene (for the time remap); steps: how many steps the run has (poses precomputed for
  // the pins); h: step length, s. Throws InputError when the character file cannot be loaded.
  CapeSystem(const ClothSpec& cloth, const CharacterSpec& character, double fps, int steps, double h);

  int particles() const override { return cloth_->particles(); }
  double h() const override { return h_; }
  const VecX& masses() const override { return cloth_->masses(); }
  // The start run's state when the scene names one (pinned particles moved onto the anchors), else the
  // cloth block's flat layout.
  void initial_state(VecX& x, VecX& v) const override;
  std::unique_ptr<StepRecord> new_record() const override { return cloth_->new_record(); }
  using System::step;
  using System::step_adjoint;
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
            StepRecord& record) override;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& record, const VecX& xhat1,
                    const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) override;
  void set_adjoint(AdjointKind kind);
  // The cloth's PCG warm start, so checkpointed rollouts recompute cape steps bit for bit.
  void save_step_context(int n, VecX& context) const override { cloth_->save_step_context(n, context); }
  void restore_step_context(int n, const VecX& context) override { cloth_->restore_step_context(n, context); }
  // The cloth's split pattern (sim/system.h's step schedule).
  StepSchedule step_schedule() const override { return cloth_->step_schedule(); }
  void hold_step_schedule(const StepSchedule& schedule) override { cloth_->hold_step_schedule(schedule); }
  void release_step_schedule() override { cloth_->release_step_schedule(); }
  std::string describe() const override;
  // Contacts of the last forward run: body_contacts (particle-steps), self_contacts (pair-steps),
  // max_body_contacts / max_self_contacts (in one step), contact_steps, cape_length (m),
  // min_body_distance (m: the smallest signed distance of a particle to the body met by the contact
  // queries in any step; negative is penetration, and a particle farther than the query radius is not seen;
  // absent when no query found a particle in range). Steps of a diverged run after the divergence keep their
  // earlier counts.
  std::vector<std::pair<std::string, double>> run_stats() const override;

  // Animation time (s) of step n and the posed body (3n vertices) at that step (allocates).
  double animation_time_at(int n) const;
  VecX body_at(int n);
  Character& character() { return character_; }
  ClothSystem& cloth() { return *cloth_; }
  const SelfCollider& self_collider() const { return *self_; }
  const BodyCollider& body_collider() const { return *body_; }

 private:
  void prepare(int n, const VecX& x, const VecX& v);  // body at step n (and its velocity), self hash of x, v
  // Pins c's top edge to the anchors (spread by arc length along them) and returns their path over the run.
  std::unique_ptr<PinTrack> anchor_track(ClothSpec& c, const CharacterSpec& character, int steps);

  CharacterSpec spec_;
  double fps_, h_;
  Character character_;
  VecX pose_, next_pose_, body_velocity_;  // body vertices at steps n and n + 1 (m), their velocity (m/s)
  int posed_step_ = -1;
  BodyCollider* body_ = nullptr;  // owned by cloth_
  SelfCollider* self_ = nullptr;  // owned by cloth_; null when self-collision is off
  std::unique_ptr<ClothSystem> cloth_;
  double cape_length_;
  // Contacts found by step n of the last forward pass (a recomputed step writes the same numbers again).
  std::vector<int> body_count_, self_count_;
  std::vector<double> min_distance_;  // smallest signed particle-body distance seen by step n (m)
};

}  // namespace kf
