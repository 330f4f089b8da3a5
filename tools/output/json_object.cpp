#include "tools/output/json_object.hpp"

#include <fmt/format.h>

#include <cmath>

namespace mpx {

namespace {

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\')
      out += {'\\', c};
    else if (static_cast<unsigned char>(c) < 0x20)
      out += fmt::format("\\u{:04x}", static_cast<int>(c));
    else
      out += c;
  }
  return out + "\"";
}

}  // namespace

JsonObject& JsonObject::addRaw(const std::string& key, const std::string& json) {
  if (!fields_.empty()) fields_ += ", ";
  fields_ += quoted(key) + ": " + json;
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, double value) {
  return addRaw(key, std::isfinite(value) ? fmt::format("{}", value) : "null");
}

JsonObject& JsonObject::add(const std::string& key, long value) { return addRaw(key, std::to_string(value)); }

JsonObject& JsonObject::add(const std::string& key, bool value) { return addRaw(key, value ? "true" : "false"); }

JsonObject& JsonObject::add(const std::string& key, const std::string& value) { return addRaw(key, quoted(value)); }

JsonObject& JsonObject::add(const std::string& key, const JsonObject& value) { return addRaw(key, value.text()); }

}  // namespace mpx
