#pragma once
// XML as the scene and URDF readers accept it: well-formed (tinyxml2), and in addition what
// XML 1.0 requires but tinyxml2 lets through, so that a file never means something other than
// what it says (docs/scene-format.md, "Input checks"):
// - references are the five predefined entities (&lt; &gt; &amp; &apos; &quot;) or character
//   references to valid XML characters; tinyxml2 keeps an undeclared "&foo;" as literal text;
// - no '<' inside an attribute value;
// - no document type declaration, whose entity definitions tinyxml2 would not expand;
// - exactly one root element;
// - for scenes, no text outside attribute values (a URDF's <gazebo> and <transmission> hold
//   text, which the importer ignores).
// A violation throws an InputError naming the file and line.
#include <tinyxml2.h>

#include <string>

namespace mpx {

enum class TextContent { Refused, Allowed };

// Parse `text` (read from `label`) into `document` and return its root element.
const tinyxml2::XMLElement& parseStrictXml(tinyxml2::XMLDocument& document, const std::string& text,
                                           const std::string& label, TextContent textContent);

}  // namespace mpx
