#pragma once
// A flat-or-nested JSON object written field by field, in insertion order (DIR/summary.json).
// Doubles are written shortest-exact (they read back to the same value); a non-finite double becomes null, as JSON has
// no NaN.
#include <string>

namespace mpx {

class JsonObject {
 public:
  JsonObject& add(const std::string& key, double value);
  JsonObject& add(const std::string& key, long value);
  JsonObject& add(const std::string& key, int value) { return add(key, static_cast<long>(value)); }
  JsonObject& add(const std::string& key, bool value);
  JsonObject& add(const std::string& key, const std::string& value);
  JsonObject& add(const std::string& key, const char* value) { return add(key, std::string(value)); }
  JsonObject& add(const std::string& key, const JsonObject& value);
  // The object's text, e.g. {"steps": 100, "status": "ok"}.
  std::string text() const { return "{" + fields_ + "}"; }

 private:
  JsonObject& addRaw(const std::string& key, const std::string& json);
  std::string fields_;
};

}  // namespace mpx
