#pragma once
// Scenes whose keyframes are reachable by construction (`keyframe bench --only reachable`).
//
// Each scene is a base scene (a sheet hanging, dropped or thrown, a cape on a character, a flock) and a
// variant that differs from it only by what the scene's controls express exactly: gravity tilted by dg
// (per-particle forces m dg reproduce it), initial velocities changed by dv + w x r (initial-velocity
// controls), or a flock pushed by one constant force per agent. The variant is simulated and its particles
// at one to three frames become the base scene's keyframe targets, so a solution exists and a miss is the
// optimiser's.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/types.h"
#include "scene/scene.h"

namespace kf {

// What separates the variant from its base scene.
struct ReachableVariant {
  Vec3 dg = Vec3::Zero();     // cloth: gravity change, m/s^2 (forces m dg on every particle)
  Vec3 dv = Vec3::Zero();     // cloth: initial velocity change of every free particle, m/s
  Vec3 omega = Vec3::Zero();  // cloth: plus omega x (x - centre of the free particles), rad/s
  Vec3 force = Vec3::Zero();  // flock: a constant horizontal force on every agent, N
};

struct ReachableScene {
  std::string name;   // "<class>-<index>"
  std::string kind;   // its class
  nlohmann::json scene;  // the scene file, keyframes included
  ReachableVariant variant;
  int keyframes = 0;
  int particles = 0;     // the sheet's particles or the flock's agents
  bool friction = false, thrown = false, character = false;
  // Drawn well conditioned only: how far a thousandth of the variant's change moves its keyframes (the largest
  // of perturbed_variant's four, in tolerances), and the draws it replaced as knife edges.
  double conditioning = -1;
  int redraws = 0;
};

// The classes, in the order the suite draws them; the last, "poncho", is outside the 100-scene suite and
// drawn only when named (--reachable-classes poncho).
const std::vector<std::string>& reachable_classes();

// The class puts its sheet on a character (the capes and the poncho).
bool reachable_class_on_character(const std::string& kind);

// Scene `index` of class `kind` for `seed` (the same arguments give the same scene). `reduced`: a small
// version (an 8 x 8 sheet or 16 agents, at most 20 frames) for tests. `directory` is where the scene file
// will live (relative asset paths are written from it). Throws std::invalid_argument for an unknown class.
// `well_conditioned`: a sheet whose keyframes a thousandth of the variant's change moves by more than a tolerance
// (a knife edge: reachable from the variant's exact change alone) is drawn again, up to 24 times; flocks as
// drawn. A scene that needs no redraw is the same scene either way.
ReachableScene generate_reachable(const std::string& kind, unsigned seed, int index, bool reduced,
                                  const std::filesystem::path& directory, bool well_conditioned = false);

// The variant with its change (dg, dv, omega, force) moved by eps of itself: scaled by 1 + eps (how 0) or 1 - eps
// (1), or turned eps off its direction one way (2) or the other (3).
ReachableVariant perturbed_variant(const ReachableVariant& v, double eps, int how);

// The variant's positions (3p) at every frame 0..frames of `base` (whose keyframes are ignored).
std::vector<VecX> simulate_variant(const Scene& base, const ReachableVariant& variant);

// The control force of every step that makes `base` follow its variant (m dg per particle, or the flock's
// force), and the initial velocities (3p) it starts with: what the tests replay.
VecX variant_step_force(const Scene& base, const ReachableVariant& variant);
VecX variant_initial_velocity(const Scene& base, const ReachableVariant& variant);

struct ReachableSweepOptions {
  unsigned seed = 52;
  int count = 100;                   // scenes, drawn over the classes by their shares
  std::vector<std::string> classes;  // only these (empty: all)
  std::vector<std::string> scenes;   // only these names (empty: all; "smoke": one a class and two more)
  bool stop_when_reached = false;    // every job with optimizer.stop_when_reached on (else the scene's)
  std::filesystem::path scene_dir = "tests/results/reachable/scenes";  // where the scene files are written
  std::filesystem::path runs_dir = "out/reachable";  // each scene's run directory
  bool generate_only = false;        // write the scene files and stop
  bool well_conditioned = false;     // draw knife edges again (generate_reachable); redraws.csv says which
  // A class table (scripts/reachable_classes.py merges the CSVs of a run split over processes): plot its pass
  // rates as a PNG beside it and stop.
  std::filesystem::path plot_classes;
  double max_seconds = 0;            // > 0: each scene's optimiser stops after this wall time (per stage)
  // A scene passes only within this many CPU seconds of its whole job (every thread), where it is cut: run
  // the bench with --threads 1 and they are the seconds the job takes on an idle core, whatever the load.
  double pass_seconds = 120;
  double wall_seconds = 900;         // and a job is cut after this wall time whatever its CPU seconds
};

// The suite's scene list for the options (name, class), in order.
std::vector<std::pair<std::string, std::string>> reachable_suite(const ReachableSweepOptions& o);

// Throws InputError when a name --reachable-scenes gives is not one of the suite's (or "smoke"): a typo would
// otherwise run nothing and exit 0. bench_reachable checks it first too.
void check_reachable_options(const ReachableSweepOptions& o);

// Generates the suite, writes each scene file, optimises each with `keyframe optimize`'s job at its
// defaults (cut at pass_seconds CPU seconds: outcome "cut") and writes reachable.csv (a row a scene, written after each), reachable_classes.csv (pass
// rate, median evaluations, median and worst seconds a class), reachable.png and load.txt.
nlohmann::json bench_reachable(const ReachableSweepOptions& o, const std::filesystem::path& out);

}  // namespace kf
