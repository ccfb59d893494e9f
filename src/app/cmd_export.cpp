// keyframe export RUN_DIR --format gltf2|pc2|obj|ply|csv: the run's animated meshes (or its particles' table)
// for other tools.
#include <algorithm>
#include <iostream>
#include <regex>

#include "app/commands.h"
#include "app/trajectory_csv.h"
#include "core/error.h"
#include "render/export/export_run.h"

namespace kf {

void add_export_command(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "export",
      "write the run's animation to RUN_DIR/export/: one animated glTF 2 (default), a point cache (.pc2 + rest "
      "OBJ per object, for Blender's Mesh Cache modifier or Maya), OBJ/PLY per frame, or every particle's position "
      "and velocity at every frame as one CSV table (csv)");
  auto req = std::make_shared<render::ExportRequest>();
  auto frames = std::make_shared<std::string>();
  auto names = std::make_shared<std::string>();
  for (const auto& n : render::export_format_names()) *names += (names->empty() ? "" : "|") + n;
  *names += "|csv";
  sub->add_option("RUN_DIR", req->run_dir, "run directory holding scene.json and trajectory.bin")->required();
  sub->add_option("--format", req->format, "file format (" + *names + ")")
      ->capture_default_str();
  sub->add_option("--frames", *frames, "frames A:B exports A..B-1 (default: all)");
  sub->footer("Objects: \"cloth\" or \"agents\", plus each mesh of RUN_DIR/meshes.bin (\"body\"); metres, Y up.\n"
              "Examples: keyframe export out/ring-toss                 (out/ring-toss/export/ring-toss.gltf + .bin)\n"
              "          keyframe export out/cape-blend --format pc2   (cloth.obj + cloth.pc2, body.obj + body.pc2)\n"
              "          keyframe export out/square --format csv       (out/square/export/trajectory.csv:\n"
              "            frame,seconds,particle,x,y,z,vx,vy,vz)\n"
              "Blender: blender -P scripts/blender_import.py -- RUN_DIR [--pc2] opens either at the run's frame\n"
              "rate; by hand, see the README's \"Bringing a run into Blender\".");
  sub->callback([=] {
    render::ExportRequest r = *req;
    if (!frames->empty()) {
      std::smatch m;
      static const std::regex re(R"((\d{1,7})?(:)?(\d{1,7})?)");
      if (!std::regex_match(*frames, m, re) || (!m[1].matched && !m[3].matched))
        throw InputError("--frames: expected A:B (frames A..B-1), A: or A, got \"" + *frames + "\"");
      r.frame_begin = m[1].matched ? std::stoi(m[1]) : 0;
      r.frame_end = m[3].matched ? std::stoi(m[3]) : (m[2].matched ? -1 : r.frame_begin + 1);
    }
    if (r.format == "csv") {
      const auto file = export_trajectory_csv(r.run_dir, r.frame_begin, r.frame_end);
      std::cout << "exported 1 file -> " << file.string() << "\n";
      return;
    }
    const auto known = render::export_format_names();
    if (std::find(known.begin(), known.end(), r.format) == known.end())
      throw InputError("unknown export format \"" + r.format + "\" (expected one of: " + *names + ")");
    const auto files = render::export_run(r);
    std::cout << "exported " << files.size() << " file" << (files.size() == 1 ? "" : "s") << " -> "
              << (r.run_dir / "export").string() << "\n";
  });
}

}  // namespace kf
