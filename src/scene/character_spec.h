#pragma once
// The animated character a cape hangs from, as the scene file states it, with the time remap of its
// animation and the run directories that give the cape's start state and end targets.
//
// Scene block (every key optional except "file"):
//   "character": {
//     "file": "../assets/character/BCN_Epileptic.X",   // relative to the scene file's directory
//     "animation": 0,
//     "time": [[0, 0.3], [30, 1.9]],   // (frame, animation seconds) keys, frames ascending; piecewise
//                                      // linear between keys, held before the first and after the last;
//                                      // default: the animation plays from its start at its own rate
//                                      // (frame f at f / fps seconds) and holds its last pose after its end
//     "scale": 1, "up_axis": "y",      // metres per file unit (0.01: centimetres) and its up axis
//                                      // ("z": (x, y, z) -> (x, z, -y)), applied first: anchors' points, the
//                                      // root's pivot and the offset are in metres, Y up
//     "loop": false,                   // a clip shorter than the scene plays again from its start
//     "offset": [0, 0, 0],             // world translation, metres
//     "root": {"pivot": [0, -1.024, 0], "axis": [1, 0, 0],   // a rigid motion on top of the animation:
//              "keys": [{"frame": 0, "translate": [0, 1.2, 0], "angle": 0}, ...]}  // translation (m) and
//                                      // rotation (degrees) about the axis through the pivot (metres, Y up),
//                                      // piecewise linear between keys, held outside them
//     "anchors": {"mesh": "Torso", "points": [[-0.18, 0.47, -0.22], ...]},
//                                      // where the cape's top edge hangs (below); or by node (bone)
//                                      // names: {"nodes": ["L_Shoulder", "Neck", "R_Shoulder"]}
//                                      // (`keyframe inspect MESH` lists them); "none": the cloth is
//                                      // not pinned to the body (its own "pins" hold); default: the
//                                      // file beside the mesh named like it with ".cape.json" (in the
//                                      // file's own units and axes), or "none" without one
//     "body": {"thickness": 0.012, "stiffness": 2000, "search": 0.06,
//              "friction": 0, "friction_velocity": 0.01},  // Coulomb coefficient, sticking speed (m/s)
//     "self": {"enabled": true, "thickness": 0.01, "stiffness": 500, "friction": 0, "friction_velocity": 0.01},
//     "start": {"run": "../out/cape-a", "frame": 39},             // initial cape state (x and v)
//     "end_target": {"run": "../out/cape-b", "frame": 51,          // adds "position" and "velocity"
//                    "position_weight": 1, "velocity_weight": 0.01} // objectives at the last frame
//   }
// The cloth block describes the cape; with anchors, its top edge is pinned to them whatever "pins" says:
// top-edge particle i of nx follows the point at arc length i / (nx - 1) along the polyline through the
// anchors' posed vertices (the edge stretches to the polyline's length; cloth.width need not match it).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/types.h"

namespace kf {
class Block;
struct Scene;

// Where a cape hangs from a character: points in the mesh file's frame (metres), or the bind-pose positions
// of named nodes (bones), ordered along the cape's top edge, each followed by the nearest bind-pose vertex of
// mesh `mesh` ("" = every mesh). It belongs to the character asset, so it is read from a file beside the
// mesh unless the scene states it.
struct CapeAnchors {
  bool none = false;               // "none": the cloth is not pinned to the body
  std::string mesh;
  std::vector<Vec3> points;        // file frame; empty when `nodes` names them
  std::vector<std::string> nodes;  // empty when `points` gives them
  std::string where;  // "file: /json/pointer" of the block, for messages about names the mesh file lacks
};

// The anchors file beside a character mesh: "body.X" -> "body.cape.json".
std::filesystem::path cape_anchors_file(const std::filesystem::path& mesh_file);
// Reads {"mesh": ..., "points": [[x, y, z], ...]} (at least 2 points). Throws InputError naming the file.
CapeAnchors load_cape_anchors(const std::filesystem::path& file);

// A keyed rigid motion of the whole character (a fall, a stunt double's drop): at each key, a translation
// and an angle about `axis` through `pivot` (file frame, before the offset).
struct RootMotion {
  Vec3 pivot = Vec3::Zero();
  Vec3 axis = Vec3::UnitX();  // unit
  struct Key {
    double frame = 0;
    Vec3 translate = Vec3::Zero();
    double angle = 0;  // degrees
  };
  std::vector<Key> keys;  // frames ascending; empty: no motion
};

struct CharacterSpec {
  std::string where;                 // "scene file: /character", for messages
  std::filesystem::path file;        // resolved against the scene's directory
  int animation = 0;
  std::vector<Vec2> time_keys{{0.0, 0.0}};  // (frame, seconds)
  Vec3 offset = Vec3::Zero();        // metres
  double scale = 1.0;                // metres per file unit
  bool z_up = false;                 // the file is Z-up: (x, y, z) -> (x, z, -y) after the scale
  bool loop = false;                 // the animation repeats (else it holds its last pose)
  RootMotion root;
  CapeAnchors anchors;
  double body_thickness = 0.012;     // m: contact springs act within this distance of the body
  double body_stiffness = 2000.0;    // N/m
  double body_search = 0.06;         // m: particles deeper than this inside the body get no force
  double body_friction = 0;          // Coulomb coefficient of the cape on the body (0: frictionless)
  double body_friction_velocity = 0.01;  // m/s: slip slower than this counts as sticking
  bool self_collision = true;
  double self_thickness = 0.01;      // m: particle pairs closer than this repel
  double self_stiffness = 500.0;     // N/m
  double self_friction = 0;          // Coulomb coefficient of cloth on cloth (0: frictionless)
  double self_friction_velocity = 0.01;  // m/s
  // Start state from a run's trajectory (empty x: the cloth block's flat layout).
  std::filesystem::path start_run;
  int start_frame = 0;
  VecX start_x, start_v;             // 3p each
  // End target from a run's trajectory (empty path: none).
  std::filesystem::path target_run;
  int target_frame = 0;
};

// Animation time (seconds) at a (fractional) frame of the scene, by the spec's keys.
double animation_time(const CharacterSpec& spec, double frame);
// Metres, Y up from the file's frame: the scale, then the rotation taking the file's up axis to +Y.
Eigen::Affine3d character_conform(const CharacterSpec& spec);
// World-from-file transform at a (fractional) frame: the conform, the root motion, then the offset.
Eigen::Affine3d character_placement(const CharacterSpec& spec, double frame);

// Reads the "character" block of a scene that already has its cloth and time; loads the start state and
// appends the end-target objectives to scene.objectives. Throws InputError with the key's JSON pointer.
CharacterSpec parse_character_spec(Block b, Scene& scene);

}  // namespace kf
