#pragma once
// Composing rendered frames into one typeset figure sheet (Cairo, DejaVu Sans): PNG pixels and a PDF
// with the same layout whose type stays vector.
#include <string>
#include <vector>

#include "render/image/png_io.h"

namespace kf::render {

struct FigureRow {
  std::string label;                  // set above the row (e.g. the scene name); empty: no label line
  std::vector<Image> tiles;           // RGB or RGBA, all the same size
  std::vector<std::string> captions;  // one per tile, set under it
};

struct FigureSheet {
  std::string title;         // set at the top; empty: no title line
  std::vector<FigureRow> rows;
  std::string caption;       // the figure's caption, set under all rows and wrapped to the sheet's width
};

// The sheet as RGB pixels: tiles at their own resolution on white. Tiles of all rows must have one size
// (else std::invalid_argument). Throws OutputError when the font (DejaVu Sans) is not installed.
Image compose_sheet(const FigureSheet& sheet);

// The same sheet as a one-page PDF (1 tile pixel = 0.75 pt, i.e. 96 dpi; tiles embedded losslessly).
std::string sheet_pdf(const FigureSheet& sheet);

// Superimposes frames (all one size, same camera) into one image: the last at full strength, earlier
// ones fainter, each contributing only where it is darker than what is already there (agents and
// cloth on a light ground).
Image overlay_frames(const std::vector<Image>& frames);

}  // namespace kf::render
