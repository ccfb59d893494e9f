#pragma once
// Builds the particle system a scene names, with only the forces and colliders it asks for.
#include <memory>

#include "scene/scene.h"
#include "sim/system.h"

namespace kf {

class ClothSystem;

// `h_override` > 0 replaces the scene's step length (gradcheck studies, coarse-to-fine).
std::unique_ptr<System> make_system(const Scene& scene, double h_override = 0);

// The sheet a system steps (a cloth scene's, or a cape's), or null (a flock).
ClothSystem* cloth_of(System& sys);

// Implemented by each family.
std::unique_ptr<System> make_flock_system(const Scene& scene, double h);
std::unique_ptr<System> make_cloth_system(const Scene& scene, double h);
std::unique_ptr<System> make_cape_system(const Scene& scene, double h);

}  // namespace kf
