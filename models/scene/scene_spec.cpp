#include "models/scene/scene_spec.hpp"

#include <fmt/format.h>

namespace mpx {

std::string SourceLocation::describe() const {
  if (line > 0) return file + ":" + std::to_string(line);
  if (index > 0) return file + ": element " + std::to_string(index);
  return file;
}

AttributeValue::AttributeValue(double value) : text_(fmt::format("{}", value)) {}

AttributeValue::AttributeValue(int value) : text_(std::to_string(value)) {}

AttributeValue::AttributeValue(const Vec3& value, int)
    : text_(fmt::format("{} {} {}", value.x(), value.y(), value.z())) {}

AttributeValue::AttributeValue(const std::vector<double>& values) : text_(fmt::format("{}", fmt::join(values, " "))) {}

AttributeValue::AttributeValue(const Eigen::Quaterniond& q)
    : text_(fmt::format("{} {} {} {}", q.w(), q.x(), q.y(), q.z())) {}

const std::string* ElementSpec::find(const std::string& name) const {
  for (const auto& [key, value] : attributes)
    if (key == name) return &value;
  return nullptr;
}

ElementSpec& ElementSpec::set(const std::string& name, const AttributeValue& value) {
  for (auto& [key, text] : attributes)
    if (key == name) {
      text = value.text();
      return *this;
    }
  attributes.emplace_back(name, value.text());
  return *this;
}

ElementSpec& SceneSpec::add(const std::string& tag, std::initializer_list<Attribute> attributes) {
  ElementSpec& element = elements.emplace_back();
  element.tag = tag;
  element.where = {label, 0, static_cast<int>(elements.size())};
  for (const Attribute& a : attributes) element.set(a.name, a.value);
  return element;
}

}  // namespace mpx
