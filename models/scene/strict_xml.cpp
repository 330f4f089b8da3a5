#include "models/scene/strict_xml.hpp"

#include "engine/core/input_error.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace mpx {

namespace {

// No element of a scene or a URDF has more than a few dozen attributes.
constexpr int kMostAttributes = 1000;

// A scan of the raw text for what the parser would accept silently; it tracks lines and whether
// it is in character data, inside a tag or inside a quoted attribute value.
class XmlTextCheck {
 public:
  XmlTextCheck(const std::string& text, const std::string& label) : text_(text), label_(label) {}

  void run() {
    enum class State { Text, Tag, Value } state = State::Text;
    char quote = 0;
    int attributes = 0;  // of the tag being read
    for (; i_ < text_.size(); ++i_) {
      const char c = text_[i_];
      if (c == '\n') ++line_;
      checkCharacter(c);
      if (state == State::Text) {
        if (startsWith("<!--")) {
          skipPast("<!--", "-->");
        } else if (startsWith("<![CDATA[")) {
          skipPast("<![CDATA[", "]]>");
        } else if (startsWith("<?")) {
          skipPast("<?", "?>");
        } else if (startsWith("<!")) {
          fail("document type declarations are not supported (their entities would not be expanded)");
        } else if (c == '<') {
          state = State::Tag;
          attributes = 0;
        } else if (c == '&') {
          checkReference();
        }
      } else if (state == State::Tag) {
        if (c == '"' || c == '\'') {
          state = State::Value, quote = c;
          // tinyxml2 checks each attribute against all before it, which takes minutes at 1e5
          if (++attributes > kMostAttributes)
            fail("an element with more than " + std::to_string(kMostAttributes) + " attributes");
        }
        if (c == '>') state = State::Text;
      } else if (c == quote) {
        state = State::Tag;
      } else if (c == '<') {
        fail("'<' inside an attribute value (write &lt;)");
      } else if (c == '&') {
        checkReference();
      }
    }
  }

 private:
  bool startsWith(const char* prefix) const {
    return text_.compare(i_, std::char_traits<char>::length(prefix), prefix) == 0;
  }

  // i_ is on `opener`: leave it on the last character of the first `terminator` after the
  // opener (or at the end: tinyxml2 reports the unterminated construct), counting the lines passed.
  void skipPast(const char* opener, const char* terminator) {
    const std::size_t end = text_.find(terminator, i_ + std::char_traits<char>::length(opener));
    const std::size_t stop =
        end == std::string::npos ? text_.size() : end + std::char_traits<char>::length(terminator) - 1;
    for (std::size_t k = i_ + 1; k < stop && k < text_.size(); ++k) {
      if (text_[k] == '\n') ++line_;
      checkCharacter(text_[k]);
    }
    i_ = stop;
  }

  // XML 1.0 allows no control characters but tab, newline and carriage return, not even in
  // comments (tinyxml2 would stop reading at a NUL)
  void checkCharacter(char c) const {
    if (static_cast<unsigned char>(c) >= 0x20 || c == '\t' || c == '\n' || c == '\r') return;
    char code[8];
    std::snprintf(code, sizeof code, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
    fail(std::string("control character ") + code + " is not allowed in XML (is this a binary file?)");
  }

  // The reference starting at i_: a predefined entity or a character reference to a valid XML
  // character (#x9, #xA, #xD, #x20-#xD7FF, #xE000-#xFFFD, #x10000-#x10FFFF).
  void checkReference() {
    const std::size_t end = text_.find(';', i_);
    if (end == std::string::npos || end - i_ > 64) fail("'&' that starts no reference (write &amp;)");
    const std::string name = text_.substr(i_ + 1, end - i_ - 1);
    for (const char* entity : {"lt", "gt", "amp", "apos", "quot"})
      if (name == entity) return;
    const std::string shown = name.substr(0, 16);
    if (name.size() < 2 || name[0] != '#')
      fail("undefined entity '&" + shown + ";' (XML predefines only lt, gt, amp, apos, quot)");
    const bool hex = name[1] == 'x';
    const std::string digits = name.substr(hex ? 2 : 1);
    const bool parsed = !digits.empty() && digits.size() <= 16 &&
                        digits.find_first_not_of(hex ? "0123456789abcdefABCDEF" : "0123456789") == std::string::npos;
    const unsigned long code = parsed ? std::strtoul(digits.c_str(), nullptr, hex ? 16 : 10) : 0;
    const bool valid = code == 0x9 || code == 0xA || code == 0xD || (code >= 0x20 && code <= 0xD7FF) ||
                       (code >= 0xE000 && code <= 0xFFFD) || (code >= 0x10000 && code <= 0x10FFFF);
    if (!parsed || !valid) fail("invalid character reference '&" + shown + ";'");
  }

  [[noreturn]] void fail(const std::string& message) const { throw InputError(label_, line_, message); }

  const std::string& text_;
  const std::string& label_;
  std::size_t i_ = 0;
  int line_ = 1;
};

// Text outside attribute values carries no meaning in a scene: reject it rather than ignore it,
// also before and after the root (an iterative walk: the element nesting is the file's, however
// deep).
void rejectText(const tinyxml2::XMLDocument& document, const std::string& label) {
  std::vector<const tinyxml2::XMLNode*> pending = {&document};
  while (!pending.empty()) {
    const tinyxml2::XMLNode* node = pending.back();
    pending.pop_back();
    for (const tinyxml2::XMLNode* child = node->FirstChild(); child; child = child->NextSibling()) {
      if (const tinyxml2::XMLText* text = child->ToText()) {
        const std::string value = text->Value();
        const std::size_t first = value.find_first_not_of(" \t\r\n");
        if (first == std::string::npos) continue;
        const std::size_t last = value.find_last_not_of(" \t\r\n");
        throw InputError(label, text->GetLineNum(),
                         "unexpected text '" + value.substr(first, std::min<std::size_t>(last + 1 - first, 32)) + "'" +
                             (node->ToElement() ? std::string(" inside <") + node->Value() + ">"
                                                : std::string(" outside the root element")));
      } else if (child->ToElement()) {
        pending.push_back(child);
      }
    }
  }
}

// What tinyxml2 found wrong, in words for its common errors, with the element it was in.
std::string malformedXml(const tinyxml2::XMLDocument& document) {
  if (document.ErrorID() == tinyxml2::XML_ERROR_EMPTY_DOCUMENT) return "the file is empty (no XML element)";
  static const std::pair<tinyxml2::XMLError, const char*> kInWords[] = {
      {tinyxml2::XML_ERROR_PARSING_ATTRIBUTE, "an attribute is not name=\"value\", or is given twice"},
      {tinyxml2::XML_ERROR_MISMATCHED_ELEMENT, "an element is closed by another name, or not closed"},
      {tinyxml2::XML_ERROR_PARSING_TEXT, "text where an element was expected"},
      {tinyxml2::XML_ERROR_PARSING, "an element is not closed before the file ends, or a tag is cut short"},
      {tinyxml2::XML_ERROR_PARSING_ELEMENT, "an element's tag is malformed"},
      {tinyxml2::XML_ERROR_PARSING_COMMENT, "a comment is not closed"},
      {tinyxml2::XML_ERROR_PARSING_DECLARATION,
       "a declaration or processing instruction is malformed, or stands inside or after the root element"},
  };
  const char* what = document.ErrorName();
  for (const auto& [error, words] : kInWords)
    if (document.ErrorID() == error) what = words;
  // tinyxml2's own text ends with the element it was reading ("... XMLElement name=mass")
  const std::string detail = document.ErrorStr();
  const std::size_t element = detail.find("XMLElement name=");
  return std::string("malformed XML: ") + what +
         (element == std::string::npos ? "" : " (in <" + detail.substr(element + 16, 64) + ">)");
}

}  // namespace

const tinyxml2::XMLElement& parseStrictXml(tinyxml2::XMLDocument& document, const std::string& text,
                                           const std::string& label, TextContent textContent) {
  XmlTextCheck(text, label).run();
  document.Parse(text.c_str(), text.size());
  if (document.Error()) throw InputError(label, std::max(1, document.ErrorLineNum()), malformedXml(document));
  const tinyxml2::XMLElement* root = document.RootElement();
  if (!root) throw InputError(label, 1, "the file holds no XML element");
  if (const tinyxml2::XMLElement* second = root->NextSiblingElement())
    throw InputError(label, second->GetLineNum(),
                     std::string("a second root element <") + second->Name() + "> after <" + root->Name() + ">");
  if (textContent == TextContent::Refused) rejectText(document, label);
  return *root;
}

}  // namespace mpx
