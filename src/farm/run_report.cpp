#include "farm/run_report.h"

#include <cmath>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/file_name.h"
#include "core/json_depth.h"

namespace kf::farm {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr std::uintmax_t kMaxFileBytes = 64u << 20;

// The file's JSON, or InputError naming it.
json read_json_file(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw InputError(file.string() + ": cannot read (" + ec.message() + ")");
  if (size > kMaxFileBytes) throw InputError(file.string() + ": larger than 64 MiB");
  std::ifstream in(file, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  check_json_depth(text, file.string());
  json j = json::parse(text, nullptr, false);
  if (j.is_discarded()) throw InputError(file.string() + ": not valid JSON");
  if (!j.is_object()) throw InputError(file.string() + ": /: expected an object, got " + std::string(j.type_name()));
  return j;
}

std::string shown(const json& v) {
  std::string s = v.dump(-1, ' ', true, json::error_handler_t::replace);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return std::string(v.type_name()) + " " + s;
}

[[noreturn]] void fail(const fs::path& file, const std::string& pointer, const std::string& expected) {
  throw InputError(file.string() + ": " + pointer + ": " + expected);
}

const json& required(const fs::path& file, const json& parent, const std::string& pointer, const char* key) {
  const auto it = parent.find(key);
  if (it == parent.end()) fail(file, pointer + "/" + key, "required key is missing");
  return *it;
}

}  // namespace

std::optional<RunReport> read_run_report(const fs::path& run_dir) {
  const fs::path file = run_dir / "report.json";
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  if (!fs::is_regular_file(file, ec)) throw InputError(file.string() + ": not a file");
  RunReport r;
  r.json = read_json_file(file);
  const json& j = r.json;
  const json& interrupted = required(file, j, "", "interrupted");
  if (!interrupted.is_boolean()) fail(file, "/interrupted", "expected true or false, got " + shown(interrupted));
  r.interrupted = interrupted.get<bool>();
  const json& status = required(file, j, "", "status");
  if (!status.is_string()) fail(file, "/status", "expected a string, got " + shown(status));
  r.status = status.get<std::string>();
  const json& objective = required(file, j, "", "final_objective");
  if (!objective.is_number() || !std::isfinite(objective.get<double>()))
    fail(file, "/final_objective", "expected a finite number, got " + shown(objective));
  r.final_objective = objective.get<double>();
  if (const auto it = j.find("evaluations"); it != j.end() && !(it->is_number_integer() && it->get<long long>() >= 0))
    fail(file, "/evaluations", "expected an integer >= 0, got " + shown(*it));
  if (const auto it = j.find("wall_seconds"); it != j.end() && !(it->is_number() && it->get<double>() >= 0))
    fail(file, "/wall_seconds", "expected a number >= 0, got " + shown(*it));
  return r;
}

SweepManifest read_sweep_manifest(const fs::path& out) {
  const fs::path file = out / "sweep.json";
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw InputError(out.string() + ": not a sweep directory (no sweep.json; made by keyframe farm optimize)");
  const json j = read_json_file(file);
  SweepManifest m;
  const json& keys = required(file, j, "", "keys");
  if (!keys.is_array()) fail(file, "/keys", "expected an array of JSON pointers, got " + shown(keys));
  for (size_t k = 0; k < keys.size(); ++k) {
    const std::string at = "/keys/" + std::to_string(k);
    if (!keys[k].is_string() || keys[k].get<std::string>().empty() || keys[k].get<std::string>()[0] != '/')
      fail(file, at, "expected a JSON pointer such as \"/cloth/stretch\", got " + shown(keys[k]));
    m.keys.push_back(keys[k].get<std::string>());
  }
  const json& runs = required(file, j, "", "runs");
  if (!runs.is_array()) fail(file, "/runs", "expected an array of runs, got " + shown(runs));
  for (size_t k = 0; k < runs.size(); ++k) {
    const std::string at = "/runs/" + std::to_string(k);
    const json& run = runs[k];
    if (!run.is_object()) fail(file, at, "expected an object, got " + shown(run));
    SweepManifest::Run r;
    const json& name = required(file, run, at, "name");
    if (!name.is_string()) fail(file, at + "/name", "expected a string, got " + shown(name));
    r.name = name.get<std::string>();
    if (const std::string why = file_name_problem(r.name); !why.empty())
      fail(file, at + "/name", "the run's directory name " + why + ", got \"" + printable(r.name) + "\"");
    const json& scene = required(file, run, at, "scene");
    if (!scene.is_string()) fail(file, at + "/scene", "expected a string, got " + shown(scene));
    r.scene = scene.get<std::string>();
    r.values = required(file, run, at, "values");
    if (!r.values.is_object()) fail(file, at + "/values", "expected an object, got " + shown(r.values));
    for (const auto& key : m.keys)
      if (!r.values.contains(key)) fail(file, at + "/values", "has no value for the key \"" + key + "\"");
    m.runs.push_back(std::move(r));
  }
  return m;
}

}  // namespace kf::farm
