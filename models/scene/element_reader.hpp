#pragma once
// Typed, validated access to the attributes of one scene element. Every value is checked
// (finite numbers, signs, vector length) and every attribute must be read: finish() rejects
// the ones left over, so a misspelt attribute is an error, not a silent default.
#include "engine/core/component.hpp"
#include "engine/core/input_error.hpp"
#include "models/scene/scene_spec.hpp"

#include <set>
#include <string>
#include <vector>

namespace mpx {

// A value as quoted in a message: whole up to 64 characters, else its start and its length;
// bytes outside printable ASCII as \xHH (printable).
std::string echoed(const std::string& value);

class ElementReader {
 public:
  explicit ElementReader(const ElementSpec& element);

  bool has(const char* attribute) const;
  std::string text(const char* attribute);
  std::string text(const char* attribute, const std::string& fallback);
  double number(const char* attribute);
  double number(const char* attribute, double fallback);
  // A number that must be > 0 (positive) or >= 0 (nonNegative).
  double positive(const char* attribute);
  double positive(const char* attribute, double fallback);
  double nonNegative(const char* attribute, double fallback);
  // An integer from `smallest` to `largest`.
  int count(const char* attribute, int fallback, int smallest, int largest);
  Vec3 vector(const char* attribute, const Vec3& fallback);
  // "true" or "false".
  bool flag(const char* attribute, bool fallback);
  // A rotation as a quaternion "w x y z" (normalised); the identity when absent.
  Eigen::Quaterniond orientation(const char* attribute);
  std::vector<double> numbers(const char* attribute);

  // Throw an InputError naming the file, line, element and `message`.
  [[noreturn]] void fail(const std::string& message) const;
  // Reject attributes that were never read.
  void finish() const;
  const ElementSpec& element() const { return element_; }
  const std::string& tag() const { return element_.tag; }
  // Where the element came from, e.g. "scene.xml:12", for messages that name it.
  std::string where() const { return element_.where.describe(); }

 private:
  const char* raw(const char* attribute);
  double parseNumber(const char* attribute, const std::string& token) const;

  const ElementSpec& element_;
  std::set<std::string> read_;
};

}  // namespace mpx
