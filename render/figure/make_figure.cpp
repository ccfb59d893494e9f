#include "render/figure/make_figure.h"

#include <algorithm>
#include <cctype>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "render/figure/figure_sheet.h"
#include "render/frame_renderer.h"

namespace kf::render {

namespace {

std::vector<int> default_frames(const RunData& run) {
  std::set<int> f = {0, run.trajectory.frames() - 1};
  for (const auto& o : run.scene.objectives)
    if (o.frame < run.trajectory.frames()) f.insert(o.frame);
  std::vector<int> v(f.begin(), f.end());
  if (v.size() > 6) {  // keep first, last and evenly spaced keyframes
    std::vector<int> picked;
    for (int k = 0; k < 6; ++k) picked.push_back(v[size_t(k * (v.size() - 1) / 5)]);
    v = picked;
  }
  return v;
}

bool is_keyframe(const RunData& run, int frame) {
  return std::any_of(run.scene.objectives.begin(), run.scene.objectives.end(),
                     [&](const auto& o) { return o.frame == frame; });
}

int last_keyframe(const RunData& run) {
  int f = -1;
  for (const auto& o : run.scene.objectives)
    if (o.frame < run.trajectory.frames()) f = std::max(f, o.frame);
  return f >= 0 ? f : run.trajectory.frames() - 1;
}

std::vector<int> resolve_frames(const RunData& run, const std::vector<int>& requested) {
  if (requested.empty()) return default_frames(run);
  std::vector<int> v;
  for (int f : requested) v.push_back(f == kLastKeyframe ? last_keyframe(run) : f == kLastFrame ? run.trajectory.frames() - 1 : f);
  return v;
}

std::string frame_caption(const RunData& run, int f) {
  return "Frame " + std::to_string(f) + (is_keyframe(run, f) ? " (keyframe)" : "");
}

std::string lower_first(std::string s) {
  if (!s.empty()) s[0] = char(std::tolower(static_cast<unsigned char>(s[0])));
  return s;
}

// Labels are set in sentence case: "ring-toss" -> "Ring toss".
std::string sentence_case(std::string s) {
  std::replace(s.begin(), s.end(), '-', ' ');
  std::replace(s.begin(), s.end(), '_', ' ');
  if (!s.empty()) s[0] = char(std::toupper(static_cast<unsigned char>(s[0])));
  return s;
}

void check_request(const FigureRequest& r) {
  if (r.run_dirs.empty()) throw InputError("figure: expected at least one run directory");
  make_backend(r.backend);  // unknown names fail before any work
  if (r.width < 16 || r.height < 16 || r.width > 4096 || r.height > 4096)
    throw InputError("figure: tile size " + std::to_string(r.width) + "x" + std::to_string(r.height) +
                     " out of range (each side 16..4096 pixels)");
  for (char c : r.name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'))
      throw InputError("figure: --name \"" + r.name + "\" may use only letters, digits, '-', '_' and '.'");
  if (!r.labels.empty() && r.labels.size() != r.run_dirs.size())
    throw InputError("figure: --labels: expected one label per run directory (" + std::to_string(r.run_dirs.size()) +
                     "), got " + std::to_string(r.labels.size()));
}

// What names each run on the sheet: its label, or its scene's name.
std::vector<std::string> run_names(const FigureRequest& r, const std::vector<RunData>& runs) {
  if (!r.labels.empty()) return r.labels;
  std::vector<std::string> names;
  for (const RunData& run : runs) names.push_back(sentence_case(run.scene.name));
  return names;
}

// Every run, read whole before any rendering; each requested frame checked against each run.
std::vector<RunData> load_runs(const FigureRequest& r) {
  std::vector<RunData> runs;
  for (const auto& d : r.run_dirs) runs.push_back(load_run(d));
  for (size_t k = 0; k < runs.size(); ++k)
    for (int f : r.frames)
      if ((f < 0 && f != kLastKeyframe && f != kLastFrame) || f >= runs[k].trajectory.frames())
        throw InputError("figure: frame " + std::to_string(f) + " out of range: " + r.run_dirs[k].string() +
                         " has frames 0.." + std::to_string(runs[k].trajectory.frames() - 1));
  return runs;
}

struct RunTiles {
  std::vector<Image> tiles;
  std::vector<std::string> captions;
};

// One run's tiles and captions, in request order (one overlaid tile with --overlay).
RunTiles render_tiles(const FigureRequest& r, const RunData& run) {
  FrameRenderer renderer(run, r.backend, {r.width, r.height, r.spp});
  const std::vector<int> frames = resolve_frames(run, r.frames);
  std::vector<Image> images;
  if (r.overlay && run.scene.flock) {
    images.push_back(renderer.render_path(frames));
  } else {
    for (int f : frames) images.push_back(renderer.render(f));
  }
  RunTiles t;
  if (r.overlay) {
    t.tiles.push_back(overlay_frames(images));
    t.captions.push_back("Frames " + std::to_string(frames.front()) + "\u2013" + std::to_string(frames.back()));
  } else {
    t.tiles = std::move(images);
    for (int f : frames) t.captions.push_back(frame_caption(run, f));
  }
  return t;
}

// One row per run; with one run and no label the sheet's title already names it.
std::vector<FigureRow> rows_by_run(const std::vector<std::string>& names, bool label_one, std::vector<RunTiles>& tiles) {
  std::vector<FigureRow> rows;
  for (size_t k = 0; k < names.size(); ++k)
    rows.push_back({names.size() > 1 || label_one ? names[k] : "", std::move(tiles[k].tiles), tiles[k].captions});
  return rows;
}

// Transposed: row i holds every run's i-th tile; each caption names its run (and frame).
std::vector<FigureRow> rows_by_column(const std::vector<std::string>& names, std::vector<RunTiles>& tiles) {
  size_t depth = 0;
  for (const auto& t : tiles) depth = std::max(depth, t.tiles.size());
  std::vector<FigureRow> rows;
  for (size_t i = 0; i < depth; ++i) {
    FigureRow row;
    bool same = true;
    for (size_t k = 0; k < names.size(); ++k)
      same = same && i < tiles[k].captions.size() && tiles[k].captions[i] == tiles[0].captions[i];
    row.label = same && i < tiles[0].captions.size() ? tiles[0].captions[i] : "";
    for (size_t k = 0; k < names.size(); ++k) {
      if (i >= tiles[k].tiles.size()) continue;
      row.tiles.push_back(std::move(tiles[k].tiles[i]));
      const std::string& run_name = names[k];
      row.captions.push_back(same ? run_name : run_name + ", " + lower_first(tiles[k].captions[i]));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

std::filesystem::path make_figure(const FigureRequest& r) {
  check_request(r);
  const std::vector<RunData> runs = load_runs(r);
  std::vector<RunTiles> tiles;
  for (const RunData& run : runs) tiles.push_back(render_tiles(r, run));
  const std::vector<std::string> names = run_names(r, runs);
  std::vector<FigureRow> rows = r.columns ? rows_by_column(names, tiles) : rows_by_run(names, !r.labels.empty(), tiles);
  const std::string name = r.name.empty() ? runs.front().scene.name : r.name;
  const FigureSheet sheet{r.title.empty() ? sentence_case(runs.front().scene.name) : r.title, std::move(rows),
                          r.caption};
  const Image pixels = compose_sheet(sheet);
  const std::string pdf = sheet_pdf(sheet);
  ensure_directory(r.out_dir);
  const auto path = r.out_dir / (name + ".png");
  write_file_atomic(r.out_dir / (name + ".pdf"), pdf);
  write_png(path, pixels);
  return path;
}

}  // namespace kf::render
