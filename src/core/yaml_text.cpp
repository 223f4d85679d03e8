#include "sg/core/yaml_text.hpp"

#include <fstream>
#include <iterator>

#include "sg/core/error.hpp"

namespace sg::core {

int flow_nesting_depth(std::string_view text) {
  int depth = 0, deepest = 0;
  char quote = 0;        // the quote character of the quoted scalar we are in, or 0
  char previous = '\n';  // the character before the current one
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote != 0) {
      if (quote == '"' && c == '\\') {
        ++i;  // an escaped character, e.g. \"
      } else if (c == quote) {
        // '' inside a single-quoted scalar is an escaped quote.
        if (quote == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
          ++i;
        } else {
          quote = 0;
        }
      }
      previous = c;
      continue;
    }
    // A quote or # starts a quoted scalar or a comment only where a token may start (an apostrophe
    // inside a plain scalar like it's does not).
    const bool token_start = previous == '\n' || previous == ' ' || previous == '\t' ||
                             previous == '[' || previous == '{' || previous == ',' ||
                             previous == ':';
    if (c == '#' && (previous == '\n' || previous == ' ' || previous == '\t')) {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
      previous = '\n';
      continue;
    }
    if ((c == '\'' || c == '"') && token_start) {
      quote = c;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
    previous = c;
  }
  return deepest;
}

void check_flow_nesting(std::string_view text, const std::string& where) {
  if (flow_nesting_depth(text) > kMaxFlowNesting) {
    throw InputError(where + ": collections ([ ] or { }) nested more than " +
                     std::to_string(kMaxFlowNesting) + " levels deep");
  }
}

std::string read_yaml_text(const std::filesystem::path& path, const std::string& where) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(where + ": cannot open the file");
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  check_flow_nesting(text, where);
  return text;
}

}  // namespace sg::core
