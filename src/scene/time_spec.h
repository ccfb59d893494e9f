#pragma once
// Time discretisation of a scene: frames at `fps`, each split into `substeps` integrator steps.
namespace kf {

struct TimeSpec {
  double fps = 30.0;
  int substeps = 1;  // integrator steps per frame
  int frames = 100;  // frames simulated after frame 0; states exist for frames 0..frames
  double h() const { return 1.0 / (fps * substeps); }
  int steps() const { return frames * substeps; }
  double duration() const { return frames / fps; }
};

}  // namespace kf
