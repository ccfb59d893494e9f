#include "farm/farm_sweep.h"

#include <cctype>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "report/plot.h"
#include "app/run_dir.h"
#include "farm/run_report.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/file_name.h"
#include "scene/scene.h"

namespace kf::farm {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// JSON's kinds as a user names them; all numbers are one kind.
std::string kind(const json& j) {
  if (j.is_number()) return "number";
  if (j.is_boolean()) return "boolean";
  if (j.is_string()) return "string";
  if (j.is_array()) return "array";
  if (j.is_object()) return "object";
  return "null";
}

// A value or name as a CSV cell or a directory name: no separators, quotes or line breaks.
std::string plain(const std::string& s, const std::string& allowed) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || allowed.find(c) != std::string::npos ? c : '_';
  return out;
}

std::string cell(const json& j) {
  if (j.is_null()) return "";
  if (j.is_string()) return plain(j.get<std::string>(), " .:;+-_=()/");
  return plain(j.dump(), ".+-_[];:");
}

}  // namespace

Sweep parse_sweep(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return InputError("--sweep " + printable(text) + ": " + why +
                      " (expected KEY=V1,V2,... with KEY a JSON pointer into the scene, "
                      "e.g. /cloth/stretch=500,2000)");
  };
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || text[0] != '/') throw bad("no key");
  Sweep s;
  s.key = text.substr(0, eq);
  try {
    (void)json::json_pointer(s.key);
  } catch (const json::exception&) {
    throw bad("\"" + s.key + "\" is not a JSON pointer");
  }
  if (has_control_character(text)) throw bad("contains a control character");
  // Split the values at top-level commas.
  const std::string list = text.substr(eq + 1);
  int depth = 0;
  bool quoted = false;
  std::string current;
  std::vector<std::string> words;
  for (size_t i = 0; i <= list.size(); ++i) {
    const char c = i < list.size() ? list[i] : ',';
    if (c == '"' && (i == 0 || list[i - 1] != '\\')) quoted = !quoted;
    if (!quoted && (c == '[' || c == '{')) ++depth;
    if (!quoted && (c == ']' || c == '}') && --depth < 0) throw bad("a ] or } without its opening bracket");
    if (i == list.size() && quoted) throw bad("an unclosed quote");
    if (i == list.size() && depth > 0) throw bad("an unclosed [ or {");
    if (c == ',' && depth == 0 && !quoted) {
      if (current.empty()) throw bad("an empty value");
      words.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  for (const auto& w : words) {
    json v = json::parse(w, nullptr, false);
    s.values.push_back(v.is_discarded() ? json(w) : v);
    s.texts.push_back(w);
  }
  return s;
}

namespace {

// Run names use each key's last token, or the whole pointer when two keys end alike.
std::vector<std::string> sweep_labels(const std::vector<Sweep>& sweeps) {
  std::vector<std::string> labels;
  std::map<std::string, int> uses;
  for (const auto& s : sweeps) ++uses[json::json_pointer(s.key).back()];
  for (const auto& s : sweeps) {
    const std::string last = json::json_pointer(s.key).back();
    std::string label = uses[last] > 1 ? s.key.substr(1) : last;
    for (char& c : label) c = c == '/' ? '.' : c;
    labels.push_back(plain(label, ".-_"));
  }
  return labels;
}

// Every swept key has a block to go into in the scene file, and every value the kind the file has there.
void check_sweeps_fit(const fs::path& file, const json& j, const std::vector<Sweep>& sweeps) {
  for (const auto& s : sweeps) {
    const json::json_pointer ptr(s.key);
    const auto parent = ptr.parent_pointer();
    if (!j.contains(parent) || !(j[parent].is_object() || j[parent].is_array()))
      throw InputError("--sweep " + s.key + ": " + file.string() + " has no " + parent.to_string() +
                       " block to set " + ptr.back() + " in");
    if (j.contains(ptr))
      for (size_t k = 0; k < s.values.size(); ++k)
        if (kind(s.values[k]) != kind(j[ptr]))
          throw InputError("--sweep " + s.key + "=" + s.texts[k] + ": " + file.string() + " has a " + kind(j[ptr]) +
                           " at " + s.key + " (" + j[ptr].dump() + "), got a " + kind(s.values[k]));
  }
}

// One scene file and what plan_sweep needs to make its runs.
struct SweepBase {
  const fs::path& file;
  const Scene& scene;
  const json& j;
  const std::vector<Sweep>& sweeps;
  const std::vector<std::string>& labels;
};

// The run at grid point `at` (an index into each sweep's values), checked as a scene.
SweepRun sweep_run(const SweepBase& b, const std::vector<size_t>& at) {
  SweepRun run;
  run.scene = b.scene.name;
  run.name = plain(b.scene.name, ".-_");
  run.file = b.j;
  run.values = json::object();
  std::string point;
  for (size_t i = 0; i < b.sweeps.size(); ++i) {
    const auto& s = b.sweeps[i];
    run.file[json::json_pointer(s.key)] = s.values[at[i]];
    run.values[s.key] = s.values[at[i]];
    run.name += "_" + b.labels[i] + "=" + plain(s.texts[at[i]], ".-+_");
    point += (point.empty() ? "" : " ") + s.key + "=" + s.texts[at[i]];
  }
  absolutise_scene_paths(run.file, b.scene.directory);
  try {
    parse_scene(run.file.dump(), b.file);
  } catch (const InputError& e) {
    throw InputError("--sweep " + point + ": " + e.what());
  }
  return run;
}

// Steps `at` to the next grid point, the first sweep varying slowest; false after the last.
bool next_grid_point(const std::vector<Sweep>& sweeps, std::vector<size_t>& at) {
  for (size_t i = sweeps.size(); i-- > 0;) {
    if (++at[i] < sweeps[i].values.size()) return true;
    at[i] = 0;
  }
  return false;
}

}  // namespace

std::vector<SweepRun> plan_sweep(const std::vector<fs::path>& scenes, const std::vector<Sweep>& sweeps) {
  const std::vector<std::string> labels = sweep_labels(sweeps);
  std::vector<SweepRun> runs;
  std::set<std::string> names;
  for (const auto& file : scenes) {
    const Scene base = load_scene(file);  // the scene itself first: its own errors read best
    const json j = json::parse(read_all(file));
    check_sweeps_fit(file, j, sweeps);
    std::vector<size_t> at(sweeps.size(), 0);
    do {
      SweepRun run = sweep_run({file, base, j, sweeps, labels}, at);
      if (!names.insert(run.name).second)
        throw InputError("two runs would both be named " + run.name + " (the same scene given twice?)");
      runs.push_back(std::move(run));
    } while (next_grid_point(sweeps, at));
  }
  return runs;
}

bool run_finished(const fs::path& run_dir) {
  const auto report = read_run_report(run_dir);
  return report && !report->interrupted;
}

json sweep_manifest(const SweepFarm& farm) {
  json m = {{"keys", farm.keys}, {"runs", json::array()}};
  for (const auto& r : farm.runs) m["runs"].push_back({{"name", r.name}, {"scene", r.scene}, {"values", r.values}});
  return m;
}

SweepPlan plan_sweep_farm(const SweepFarm& farm) {
  slurm::check(farm.slurm);
  SweepPlan plan;
  for (size_t k = 0; k < farm.runs.size(); ++k)
    if (!run_finished(farm.out / farm.runs[k].name)) plan.todo.push_back(k);

  const std::string kf = slurm::shell_quote(farm.keyframe.string());
  const std::string out = slurm::shell_quote(farm.out.string());
  const std::string logs = slurm::shell_quote((farm.out / "farm" / "logs").string());
  const std::string name = slurm::job_name(farm.out.filename().string());
  std::string keys;
  for (const auto& k : farm.keys) keys += (keys.empty() ? "" : ", ") + k;
  std::string runs;
  for (size_t k : plan.todo) runs += (runs.empty() ? "" : " ") + farm.runs[k].name;

  std::string s = "#!/bin/bash\n";
  s += "# keyframe farm optimize: " + std::to_string(plan.todo.size()) + " of " + std::to_string(farm.runs.size()) +
       " runs" + (keys.empty() ? "" : " over " + keys) + ", each into " + farm.out.string() + "/RUN\n";
  s += "#SBATCH --job-name=keyframe-optimize-" + name + "\n";
  s += "#SBATCH --array=0-" + std::to_string(int(plan.todo.size()) - 1) + "\n";
  s += "#SBATCH --output=" + logs + "/optimize-%A_%a.out\n";
  s += slurm::sbatch_lines(farm.slurm);
  s += "set -euo pipefail\n";
  s += "keyframe=" + kf + "\n";
  s += "runs=(" + runs + ")\n";
  s += "run=${runs[$SLURM_ARRAY_TASK_ID]}\n";
  s += "cd " + out + "\n";
  // Exit 7 (the keyframes were not reached) is a finished run of the sweep: its report says why.
  s += "\"$keyframe\" --threads \"${SLURM_CPUS_PER_TASK:-0}\" optimize \"scenes/$run.json\" --out \"$run\" "
       "--quiet" +
       (farm.max_evaluations >= 0 ? " --max-evaluations " + std::to_string(farm.max_evaluations) : "") +
       " || [ $? -eq 7 ]\n";
  plan.optimize_script = s;

  s = "#!/bin/bash\n";
  s += "# keyframe farm optimize: gather the runs' report.json into " + farm.out.string() +
       "/sweep.csv and sweep.png\n";
  s += "#SBATCH --job-name=keyframe-gather-" + name + "\n";
  s += "#SBATCH --output=" + logs + "/gather-%j.out\n";
  s += slurm::sbatch_lines(farm.slurm);
  s += "set -euo pipefail\n";
  s += "exec " + kf + " farm gather " + out + "\n";
  plan.gather_script = s;
  return plan;
}

std::vector<std::string> gather_sweep(const fs::path& out) {
  const SweepManifest m = read_sweep_manifest(out);
  const auto& keys = m.keys;

  // Scalar numbers of each report's measures and final terms become columns, in the order first met.
  // Every report is read (and validated) before anything is written.
  const char* fixed[] = {"evaluations", "wall_seconds", "initial_objective", "final_objective"};
  std::vector<std::string> extra;
  std::set<std::string> seen;
  std::vector<json> reports;
  std::vector<std::string> unfinished;
  for (const auto& run : m.runs) {
    json flat;
    const auto report = read_run_report(out / run.name);
    if (report && !report->interrupted) {
      flat = report->json.flatten();
      for (const auto& [k, v] : flat.items())
        if (v.is_number() && (k.rfind("/measures/", 0) == 0 || k.rfind("/final_terms/", 0) == 0) &&
            seen.insert(k).second)
          extra.push_back(k);
    } else {
      unfinished.push_back(run.name);
    }
    reports.push_back(flat);
  }
  std::ostringstream csv;
  csv << std::setprecision(10) << "run,scene";
  for (const auto& k : keys) csv << "," << plain(k, "/._-");
  for (const char* f : fixed) csv << "," << f;
  for (const auto& k : extra) csv << "," << plain(k.substr(1), "/._-");
  csv << ",status\n";
  for (size_t i = 0; i < reports.size(); ++i) {
    const auto& run = m.runs[i];
    const json& r = reports[i];
    csv << cell(run.name) << "," << cell(run.scene);
    for (const auto& k : keys) csv << "," << cell(run.values[k]);
    for (const char* f : fixed) csv << "," << (r.contains(std::string("/") + f) ? cell(r[std::string("/") + f]) : "");
    for (const auto& k : extra) csv << "," << (r.contains(k) ? cell(r[k]) : "");
    csv << "," << (r.is_null() ? "not finished" : cell(r.value("/status", json("finished")))) << "\n";
  }
  write_file_atomic(out / "sweep.csv", csv.str());

  // One numeric sweep over one scene: final objective against the value; otherwise a bar per run.
  const int final_col = 2 + int(keys.size()) + 4;
  bool numeric = keys.size() == 1;
  std::set<std::string> scenes;
  for (const auto& run : m.runs) {
    scenes.insert(run.scene);
    if (numeric && !run.values[keys[0]].is_number()) numeric = false;
  }
  const std::string title = out.filename().string() + ": final objective";
  if (numeric && scenes.size() == 1)
    plot_csv(out / "sweep.csv", out / "sweep.png", title, 3, {final_col}, true);
  else
    bar_plot_csv(out / "sweep.csv", out / "sweep.png", title, {1}, {final_col}, true);
  return unfinished;
}

}  // namespace kf::farm
