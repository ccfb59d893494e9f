#pragma once
// Pinned particles of a mesh cloth worn by a character (a poncho's collar): each follows the skin vertex
// nearest its rest position in the frame-0 pose, keeping its offset from that vertex, so the collar moves
// with the body without jumping at frame 0 (a grid cape hangs its top edge on the anchors instead).
#include <memory>
#include <vector>

#include "scene/character_spec.h"
#include "scene/cloth_spec.h"
#include "sim/character/character.h"
#include "sim/cloth/pin_track.h"

namespace kf {

class SkinPinTrack final : public PinTrack {
 public:
  // table[n][slot]: where pinned particle `pinned[slot]` is at step n = 0 .. N (m); h: step length (s).
  SkinPinTrack(std::vector<std::vector<Vec3>> table, const std::vector<int>& pinned, int particles, double h);
  // Steps past N hold the last position with zero velocity; velocity is the forward difference to n + 1.
  void state(int n, int particle, const Vec3& x0, Vec3& position, Vec3& velocity) const override;

 private:
  std::vector<std::vector<Vec3>> table_;
  std::vector<int> slot_;  // particle -> slot, -1 if not pinned
  double h_;
};

// The track of `cloth.pins` (at least one, or InputError naming the scene's cloth/pins) over steps 0 .. steps + 1,
// following the vertices of `character.anchors.mesh` ("" = every mesh).
std::unique_ptr<SkinPinTrack> skin_pin_track(Character& body, const CharacterSpec& character, const ClothSpec& cloth,
                                             double fps, int steps, double h);

}  // namespace kf
