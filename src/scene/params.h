#pragma once
// Reading one JSON block of a scene with explicit defaults; every key must be read or it is an error.
//
// Errors are one line: "<file>: <json pointer>: <what was expected>, got <what was there>".
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/types.h"

namespace kf {

using Json = nlohmann::json;

// One key a parse read: for `keyframe inspect SCENE` (the scene with every default filled in) and
// `keyframe schema` (each key's type, range, default and choices).
struct ParamRead {
  std::string pointer;  // JSON pointer of the key, array indices included: "/objectives/0/weight"
  std::string type;     // number, integer, boolean, string, vec3, points2, points3, numbers, integers, object, array
  bool required = false;  // false for a key the parser first asked about with has(): read only when present
  Json default_value;   // used when the key is absent (null: required, or no default)
  double lo = 0, hi = 0;  // range of the value, or of each of its numbers
  int min_count = 0;      // lists: at least this many entries
  std::vector<std::string> choices;  // strings: the values allowed (empty: any)
};

// What a whole parse read. Blocks made by child() and array() write to their parent's log.
struct ParamLog {
  std::vector<ParamRead> reads;
  Json resolved;  // the file as read, with every absent key that has a default filled in
};

class Block {
 public:
  // `file` is used in messages only; `pointer` is the JSON pointer of `j` ("" for the root).
  Block(const Json& j, std::string file, std::string pointer = "");

  // Whether the key is present. A key asked about is optional: its read is logged as not required.
  bool has(const std::string& key) const;
  double number(const std::string& key, double def, double lo, double hi);
  double number(const std::string& key, double lo, double hi);  // required
  int integer(const std::string& key, int def, int lo, int hi);
  int integer(const std::string& key, int lo, int hi);  // required
  bool boolean(const std::string& key, bool def);
  std::string string(const std::string& key, const std::string& def, const std::vector<std::string>& choices = {});
  std::string string(const std::string& key, const std::vector<std::string>& choices = {});  // required
  Vec3 vec3(const std::string& key, const Vec3& def, double lo = -1e6, double hi = 1e6);
  Vec3 vec3(const std::string& key, double lo = -1e6, double hi = 1e6);  // required
  // A list of 2-D points [[a, b], ...] with at least `min_count` entries.
  std::vector<Vec2> points2(const std::string& key, int min_count, double lo = -1e6, double hi = 1e6);
  std::vector<Vec3> points3(const std::string& key, int min_count, double lo = -1e6, double hi = 1e6);
  std::vector<double> numbers(const std::string& key, int min_count, double lo, double hi);
  std::vector<int> integers(const std::string& key, int min_count, int lo, int hi);
  std::vector<std::string> strings(const std::string& key, int min_count);

  // Nested blocks. `child` of a missing optional key gives a Block over an empty object.
  Block child(const std::string& key);
  std::optional<Block> optional_child(const std::string& key);
  std::vector<Block> array(const std::string& key, int min_count = 0);

  // Throws InputError naming the first key nobody read.
  void finish() const;
  [[noreturn]] void fail(const std::string& key, const std::string& expected) const;
  [[noreturn]] void fail_here(const std::string& expected) const;
  // `rel`: an escaped pointer below this block, such as "/targets/2".
  [[noreturn]] void fail_rel(const std::string& rel, const std::string& expected) const;
  std::string pointer(const std::string& key) const;
  const std::string& file() const { return file_; }
  const std::string& json_pointer() const { return pointer_; }  // "" for the root
  const Json& json() const { return j_; }
  // Record every key read from here on (and in the blocks made from this one) into `log` (may be null).
  void set_log(ParamLog* log) { log_ = log; }

 private:
  const Json* find(const std::string& key);
  const Json& required(const std::string& key);
  double as_number(const Json& v, const std::string& key, double lo, double hi) const;
  static std::string describe(const Json& v);
  static std::string rel(const std::string& key);
  void note(const std::string& key, ParamRead r);  // into log_, if any


  Json j_;
  std::string file_, pointer_;
  std::set<std::string> read_;
  mutable std::set<std::string> asked_;  // keys has() was asked about
  ParamLog* log_ = nullptr;
};

// Escapes a key for use inside a JSON pointer (RFC 6901).
std::string pointer_escape(const std::string& key);

}  // namespace kf
