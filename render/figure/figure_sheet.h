#pragma once
// Composing rendered frames into one labelled figure sheet.
#include <string>
#include <vector>

#include "render/image/png_io.h"

namespace kf::render {

struct FigureRow {
  std::string label;                  // drawn above the row (e.g. the scene name)
  std::vector<Image> tiles;           // RGB, all the same size
  std::vector<std::string> captions;  // one per tile, drawn under it
};

// Rows of tiles on a white sheet with a title, row labels and captions. Tiles of all rows must have
// one size. Returns RGB.
Image compose_sheet(const std::string& title, const std::vector<FigureRow>& rows);

// Superimposes frames (all one size, same camera) into one image: the last at full strength, earlier
// ones fainter, each contributing only where it is darker than what is already there (agents and
// cloth on a light ground).
Image overlay_frames(const std::vector<Image>& frames);

}  // namespace kf::render
