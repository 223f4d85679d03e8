#pragma once
/// Limits checked on the text of a YAML or JSON file before it goes to yaml-cpp. yaml-cpp 0.7
/// parses nested collections by recursion, one level per `[` or `{`, and refuses only at a few
/// hundred levels, deep in the stack; a file of stereoguard's (config, scenario, camera.yaml,
/// calibration) nests at most 6 levels.
#include <filesystem>
#include <string>
#include <string_view>

namespace sg::core {

/// Deepest flow nesting allowed in a YAML or JSON file: `[` and `{` inside one another.
constexpr int kMaxFlowNesting = 32;

/// The deepest nesting of flow collections (`[...]`, `{...}`) in `text`. Brackets inside quoted
/// scalars ('...', "...") and comments (# to the end of the line) do not count; an unclosed
/// bracket counts until the end of the text.
int flow_nesting_depth(std::string_view text);

/// Throws InputError "<where>: collections ([ ] or { }) nested more than 32 levels deep" when
/// flow_nesting_depth(text) > kMaxFlowNesting.
void check_flow_nesting(std::string_view text, const std::string& where);

/// The whole text of the YAML or JSON file `path`, passed through check_flow_nesting; throws
/// InputError "<where>: cannot open the file" when it cannot be opened.
std::string read_yaml_text(const std::filesystem::path& path, const std::string& where);

}  // namespace sg::core
