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

class Block {
 public:
  // `file` is used in messages only; `pointer` is the JSON pointer of `j` ("" for the root).
  Block(const Json& j, std::string file, std::string pointer = "");

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
  const Json& json() const { return j_; }

 private:
  const Json* find(const std::string& key);
  const Json& required(const std::string& key);
  double as_number(const Json& v, const std::string& key, double lo, double hi) const;
  static std::string describe(const Json& v);
  static std::string rel(const std::string& key);

  Json j_;
  std::string file_, pointer_;
  std::set<std::string> read_;
};

// Escapes a key for use inside a JSON pointer (RFC 6901).
std::string pointer_escape(const std::string& key);

}  // namespace kf
