#include "models/scene/element_reader.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace mpx {

std::string echoed(const std::string& value) {
  constexpr std::size_t kLongest = 64;
  const std::string shown = printable(value.substr(0, kLongest));
  if (value.size() <= kLongest) return shown;
  return shown + "... (" + std::to_string(value.size()) + " characters)";
}

ElementReader::ElementReader(const ElementSpec& element) : element_(element) {}

void ElementReader::fail(const std::string& message) const {
  std::string what = "<" + element_.tag;
  if (const std::string* name = element_.find("name")) what += " name=\"" + echoed(*name) + "\"";
  throw InputError(element_.where.describe() + ": " + what + ">: " + message);
}

bool ElementReader::has(const char* attribute) const { return element_.find(attribute) != nullptr; }

const char* ElementReader::raw(const char* attribute) {
  read_.insert(attribute);
  const std::string* value = element_.find(attribute);
  return value ? value->c_str() : nullptr;
}

std::string ElementReader::text(const char* attribute) {
  const char* value = raw(attribute);
  if (value) return value;
  // name what is there, so a misspelt attribute is easy to spot
  std::string present;
  for (const auto& [name, value] : element_.attributes) present += (present.empty() ? "" : ", ") + name;
  fail(std::string("missing required attribute '") + attribute +
       "' (attributes given: " + (present.empty() ? "none" : present) + ")");
}

std::string ElementReader::text(const char* attribute, const std::string& fallback) {
  const char* value = raw(attribute);
  return value ? value : fallback;
}

double ElementReader::parseNumber(const char* attribute, const std::string& token) const {
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (token.empty() || *end != '\0')
    fail(std::string("attribute '") + attribute + "': '" + echoed(token) + "' is not a number");
  if (!std::isfinite(value))
    fail(std::string("attribute '") + attribute + "' must be finite, got '" + echoed(token) + "'");
  return value;
}

double ElementReader::number(const char* attribute) {
  const std::string token = text(attribute);
  return parseNumber(attribute, token);
}

double ElementReader::number(const char* attribute, double fallback) {
  return has(attribute) ? number(attribute) : (read_.insert(attribute), fallback);
}

double ElementReader::positive(const char* attribute) {
  const double value = number(attribute);
  if (!(value > 0.0))
    fail(std::string("attribute '") + attribute + "' must be positive, got " + echoed(text(attribute)));
  return value;
}

double ElementReader::positive(const char* attribute, double fallback) {
  return has(attribute) ? positive(attribute) : (read_.insert(attribute), fallback);
}

double ElementReader::nonNegative(const char* attribute, double fallback) {
  const double value = number(attribute, fallback);
  if (value < 0.0)
    fail(std::string("attribute '") + attribute + "' must not be negative, got " + echoed(text(attribute)));
  return value;
}

int ElementReader::count(const char* attribute, int fallback, int smallest, int largest) {
  const double value = number(attribute, fallback);
  if (value < smallest || value > largest || value != std::floor(value))
    fail(std::string("attribute '") + attribute + "' must be an integer from " + std::to_string(smallest) + " to " +
         std::to_string(largest) + ", got " + echoed(text(attribute)));
  return static_cast<int>(value);
}

std::vector<double> ElementReader::numbers(const char* attribute) {
  std::istringstream stream(text(attribute));
  std::vector<double> values;
  for (std::string token; stream >> token;) values.push_back(parseNumber(attribute, token));
  return values;
}

Vec3 ElementReader::vector(const char* attribute, const Vec3& fallback) {
  if (!has(attribute)) {
    read_.insert(attribute);
    return fallback;
  }
  const std::vector<double> values = numbers(attribute);
  if (values.size() != 3)
    fail(std::string("attribute '") + attribute + "' needs 3 numbers, got " + std::to_string(values.size()));
  return {values[0], values[1], values[2]};
}

bool ElementReader::flag(const char* attribute, bool fallback) {
  const std::string value = text(attribute, fallback ? "true" : "false");
  if (value != "true" && value != "false")
    fail(std::string("attribute '") + attribute + "' must be 'true' or 'false', got '" + value + "'");
  return value == "true";
}

Eigen::Quaterniond ElementReader::orientation(const char* attribute) {
  if (!has(attribute)) {
    read_.insert(attribute);
    return Eigen::Quaterniond::Identity();
  }
  const std::vector<double> q = numbers(attribute);
  if (q.size() != 4) fail(std::string("attribute '") + attribute + "' needs a quaternion: 4 numbers w x y z");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (!(rotation.norm() > 0.0)) fail(std::string("attribute '") + attribute + "' must not be the zero quaternion");
  return rotation.normalized();
}

void ElementReader::finish() const {
  for (const auto& [name, value] : element_.attributes)
    if (!read_.count(name)) fail("unknown attribute '" + name + "'");
}

}  // namespace mpx
