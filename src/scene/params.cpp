#include "scene/params.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace kf {

std::string pointer_escape(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

Block::Block(const Json& j, std::string file, std::string pointer)
    : j_(j), file_(std::move(file)), pointer_(std::move(pointer)) {
  if (!j_.is_object()) fail_here("expected an object, got " + describe(j_));
}

std::string Block::pointer(const std::string& key) const { return pointer_ + "/" + pointer_escape(key); }

void Block::fail(const std::string& key, const std::string& expected) const {
  fail_rel("/" + pointer_escape(key), expected);
}

void Block::fail_rel(const std::string& rel, const std::string& expected) const {
  throw InputError(file_ + ": " + pointer_ + rel + ": " + expected);
}

std::string Block::rel(const std::string& key) { return "/" + pointer_escape(key); }

void Block::fail_here(const std::string& expected) const {
  throw InputError(file_ + ": " + (pointer_.empty() ? std::string("/") : pointer_) + ": " + expected);
}

std::string Block::describe(const Json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  const char* type = v.type_name();
  return std::string(type) + " " + s;
}

bool Block::has(const std::string& key) const {
  asked_.insert(key);
  return j_.contains(key);
}

void Block::note(const std::string& key, ParamRead r) {
  if (!log_) return;
  r.pointer = pointer(key);
  if (asked_.count(key)) r.required = false;
  if (!j_.contains(key) && !r.default_value.is_null()) log_->resolved[Json::json_pointer(r.pointer)] = r.default_value;
  log_->reads.push_back(std::move(r));
}

namespace {
ParamRead read_of(const char* type, bool required, Json def, double lo = 0, double hi = 0, int min_count = 0) {
  ParamRead r;
  r.type = type;
  r.required = required;
  r.default_value = std::move(def);
  r.lo = lo, r.hi = hi, r.min_count = min_count;
  return r;
}
Json vec_json(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }
}  // namespace

const Json* Block::find(const std::string& key) {
  read_.insert(key);
  auto it = j_.find(key);
  return it == j_.end() ? nullptr : &*it;
}

const Json& Block::required(const std::string& key) {
  const Json* v = find(key);
  if (!v) fail(key, "required key is missing");
  return *v;
}

double Block::as_number(const Json& v, const std::string& at, double lo, double hi) const {
  if (!v.is_number()) fail_rel(at, "expected a number, got " + describe(v));
  double d = v.get<double>();
  if (!std::isfinite(d)) fail_rel(at, "expected a finite number");
  if (d < lo || d > hi) {
    std::ostringstream os;
    os << "expected a number in [" << lo << ", " << hi << "], got " << d;
    fail_rel(at, os.str());
  }
  return d;
}

double Block::number(const std::string& key, double def, double lo, double hi) {
  note(key, read_of("number", false, def, lo, hi));
  const Json* v = find(key);
  return v ? as_number(*v, rel(key), lo, hi) : def;
}

double Block::number(const std::string& key, double lo, double hi) {
  note(key, read_of("number", true, nullptr, lo, hi));
  return as_number(required(key), rel(key), lo, hi);
}

static int to_int(const Block& b, const Json& v, const std::string& at, int lo, int hi) {
  if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) == v.get<double>() &&
                                   std::isfinite(v.get<double>())))
    b.fail_rel(at, "expected an integer, got " + std::string(v.type_name()) + " " + v.dump());
  double d = v.get<double>();
  if (d < lo || d > hi)
    b.fail_rel(at, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + v.dump());
  return int(d);
}

int Block::integer(const std::string& key, int def, int lo, int hi) {
  note(key, read_of("integer", false, def, lo, hi));
  const Json* v = find(key);
  return v ? to_int(*this, *v, rel(key), lo, hi) : def;
}

int Block::integer(const std::string& key, int lo, int hi) {
  note(key, read_of("integer", true, nullptr, lo, hi));
  return to_int(*this, required(key), rel(key), lo, hi);
}

bool Block::boolean(const std::string& key, bool def) {
  note(key, read_of("boolean", false, def));
  const Json* v = find(key);
  if (!v) return def;
  if (!v->is_boolean()) fail(key, "expected true or false, got " + describe(*v));
  return v->get<bool>();
}

static std::string check_choice(const Block& b, const std::string& key, const std::string& s,
                                const std::vector<std::string>& choices) {
  if (choices.empty()) return s;
  for (const auto& c : choices)
    if (c == s) return s;
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + ("\"" + c + "\"");
  b.fail(key, "expected one of " + list + ", got \"" + s + "\"");
}

std::string Block::string(const std::string& key, const std::string& def, const std::vector<std::string>& choices) {
  ParamRead r = read_of("string", false, def);
  r.choices = choices;
  note(key, std::move(r));
  const Json* v = find(key);
  if (!v) return def;
  if (!v->is_string()) fail(key, "expected a string, got " + describe(*v));
  return check_choice(*this, key, v->get<std::string>(), choices);
}

std::string Block::string(const std::string& key, const std::vector<std::string>& choices) {
  ParamRead r = read_of("string", true, nullptr);
  r.choices = choices;
  note(key, std::move(r));
  const Json& v = required(key);
  if (!v.is_string()) fail(key, "expected a string, got " + describe(v));
  return check_choice(*this, key, v.get<std::string>(), choices);
}

std::vector<double> Block::numbers(const std::string& key, int min_count, double lo, double hi) {
  note(key, read_of("numbers", true, nullptr, lo, hi, min_count));
  const Json& v = required(key);
  if (!v.is_array() || int(v.size()) < min_count)
    fail(key, "expected an array of at least " + std::to_string(min_count) + " numbers, got " + describe(v));
  std::vector<double> out;
  for (size_t i = 0; i < v.size(); ++i) out.push_back(as_number(v[i], rel(key) + "/" + std::to_string(i), lo, hi));
  return out;
}

std::vector<int> Block::integers(const std::string& key, int min_count, int lo, int hi) {
  note(key, read_of("integers", true, nullptr, lo, hi, min_count));
  const Json& v = required(key);
  if (!v.is_array() || int(v.size()) < min_count)
    fail(key, "expected an array of at least " + std::to_string(min_count) + " integers, got " + describe(v));
  std::vector<int> out;
  for (size_t i = 0; i < v.size(); ++i) out.push_back(to_int(*this, v[i], rel(key) + "/" + std::to_string(i), lo, hi));
  return out;
}

std::vector<std::string> Block::strings(const std::string& key, int min_count) {
  note(key, read_of("strings", true, nullptr, 0, 0, min_count));
  const Json& v = required(key);
  if (!v.is_array() || int(v.size()) < min_count)
    fail(key, "expected a list of at least " + std::to_string(min_count) + " strings, got " + describe(v));
  std::vector<std::string> out;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_string()) fail_rel(rel(key) + "/" + std::to_string(i), "expected a string, got " + describe(v[i]));
    out.push_back(v[i].get<std::string>());
  }
  return out;
}

static Vec3 to_vec3(const Block& b, const Json& v, const std::string& at, double lo, double hi) {
  if (!v.is_array() || v.size() != 3) b.fail_rel(at, "expected [x, y, z], got " + std::string(v.type_name()) + " " + v.dump());
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>()) || v[i].get<double>() < lo || v[i].get<double>() > hi)
      b.fail_rel(at + "/" + std::to_string(i), "expected a finite number in [" + std::to_string(lo) + ", " +
                                                 std::to_string(hi) + "], got " + v[i].dump());
    out[i] = v[i].get<double>();
  }
  return out;
}

Vec3 Block::vec3(const std::string& key, const Vec3& def, double lo, double hi) {
  note(key, read_of("vec3", false, vec_json(def), lo, hi));
  const Json* v = find(key);
  return v ? to_vec3(*this, *v, rel(key), lo, hi) : def;
}

Vec3 Block::vec3(const std::string& key, double lo, double hi) {
  note(key, read_of("vec3", true, nullptr, lo, hi));
  return to_vec3(*this, required(key), rel(key), lo, hi);
}

std::vector<Vec2> Block::points2(const std::string& key, int min_count, double lo, double hi) {
  note(key, read_of("points2", true, nullptr, lo, hi, min_count));
  const Json& v = required(key);
  if (!v.is_array() || int(v.size()) < min_count)
    fail(key, "expected a list of at least " + std::to_string(min_count) + " [a, b] points, got " + describe(v));
  std::vector<Vec2> out;
  for (size_t i = 0; i < v.size(); ++i) {
    const Json& p = v[i];
    const std::string k = rel(key) + "/" + std::to_string(i);
    if (!p.is_array() || p.size() != 2) fail_rel(k, "expected [a, b], got " + describe(p));
    Vec2 q(as_number(p[0], k + "/0", lo, hi), as_number(p[1], k + "/1", lo, hi));
    out.push_back(q);
  }
  return out;
}

std::vector<Vec3> Block::points3(const std::string& key, int min_count, double lo, double hi) {
  note(key, read_of("points3", true, nullptr, lo, hi, min_count));
  const Json& v = required(key);
  if (!v.is_array() || int(v.size()) < min_count)
    fail(key, "expected a list of at least " + std::to_string(min_count) + " [x, y, z] points, got " + describe(v));
  std::vector<Vec3> out;
  for (size_t i = 0; i < v.size(); ++i) out.push_back(to_vec3(*this, v[i], rel(key) + "/" + std::to_string(i), lo, hi));
  return out;
}

Block Block::child(const std::string& key) {
  note(key, read_of("object", false, nullptr));
  const Json* v = find(key);
  if (v && !v->is_object()) fail(key, "expected an object, got " + describe(*v));
  Block b(v ? *v : Json::object(), file_, pointer(key));
  b.log_ = log_;
  return b;
}

std::optional<Block> Block::optional_child(const std::string& key) {
  if (!has(key)) {
    note(key, read_of("object", false, nullptr));
    read_.insert(key);
    return std::nullopt;
  }
  return child(key);
}

std::vector<Block> Block::array(const std::string& key, int min_count) {
  note(key, read_of("array", min_count > 0, min_count > 0 ? Json() : Json::array(), 0, 0, min_count));
  const Json* v = find(key);
  if (!v) {
    if (min_count > 0) fail(key, "required key is missing");
    return {};
  }
  if (!v->is_array() || int(v->size()) < min_count)
    fail(key, "expected an array of at least " + std::to_string(min_count) + " objects, got " + describe(*v));
  std::vector<Block> out;
  for (size_t i = 0; i < v->size(); ++i) {
    if (!(*v)[i].is_object()) fail_rel(rel(key) + "/" + std::to_string(i), "expected an object, got " + describe((*v)[i]));
    out.emplace_back((*v)[i], file_, pointer(key) + "/" + std::to_string(i));
    out.back().log_ = log_;
  }
  return out;
}

void Block::finish() const {
  for (auto it = j_.begin(); it != j_.end(); ++it)
    if (!read_.count(it.key())) fail(it.key(), "unknown key (check its spelling; see README 'Scene files')");
}

}  // namespace kf
