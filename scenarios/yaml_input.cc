#include "scenarios/yaml_input.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include "common/error.h"
#include "common/paths.h"
#include "common/text_check.h"

namespace hexbite::yaml_input {

namespace fs = std::filesystem;

SourceLocation Source::locate(const YAML::Node& node, const SourceLocation& fallback, bool use_mark) const {
  for (const GraftedNode& g : grafted)
    if (g.node.is(node)) return g.at;
  const YAML::Mark mark = node.Mark();
  if (!use_mark || mark.is_null()) return fallback;
  return {file, mark.line + 1, mark.column + 1, note};
}

fs::path Source::folder_of(const YAML::Node& node) const {
  for (const GraftedNode& g : grafted)
    if (g.node.is(node)) return g.folder;
  return folder;
}

[[noreturn]] void fail(const SourceLocation& where, const std::string& message) {
  throw InputError(where.str() + ": " + message);
}

bool decimal_whole_number(const YAML::Node& node, long long* value) {
  if (!node.IsScalar() || is_quoted(node)) return false;
  const std::string& text = node.Scalar();
  if (text.find_first_of("xXoO") != std::string::npos) return false;
  double x = 0;
  const std::size_t digits = !text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0;  // after a sign
  if (text.size() > digits && text.find_first_not_of("0123456789", digits) == std::string::npos)
    x = std::stod(text);  // decimal, leading zeros and all
  else if (!YAML::convert<double>::decode(node, x) || !std::isfinite(x) || x != std::floor(x))
    return false;
  if (std::abs(x) > 9007199254740992.0) return false;  // 2^53: beyond it a double holds no exact integer
  *value = static_cast<long long>(x);
  return true;
}

std::string to_string(const Value& v, const std::string& hint) {
  // `name: ""` read "must be text, found the quoted text """, which is text.
  if (v.node.IsScalar() && v.node.Scalar().empty()) fail(v.at, v.path + " is empty; " + hint);
  if (!v.node.IsScalar()) fail(v.at, v.path + " must be text, found " + describe(v.node) + "; " + hint);
  return v.node.Scalar();
}

std::string to_name(const Value& v, const std::string& hint) {
  const std::string name = to_string(v, hint);
  const std::string problem = control_character_problem(name);
  if (!problem.empty())
    fail(v.at, v.path + " " + problem +
                   "; a name is one line of printable text: remove it (in YAML, '\\n' in double quotes is a "
                   "line break)");
  return name;
}

std::vector<Value> to_list(const Value& v) {
  std::vector<Value> items;
  if (v.node.IsNull()) return items;
  if (!v.node.IsSequence())
    fail(v.at, v.path + " must be a list, found " + describe(v.node) + "; write one '- ...' line per entry");
  for (size_t i = 0; i < v.node.size(); ++i) {
    const YAML::Node item = v.node[i];
    items.push_back({v.source, item, v.source->locate(item, v.at), v.path + "[" + std::to_string(i) + "]"});
  }
  return items;
}

Map::Map(const Value& v, std::vector<std::string> valid, std::string document)
    : at_(v.at), path_(v.path), document_(std::move(document)) {
  if (v.node.IsNull()) return;  // "mesh:" with nothing after it reads as an empty mapping
  if (!v.node.IsMap())
    fail(v.at, what() + " must be a mapping of 'key: value' entries, found " + describe(v.node) +
                   "; valid keys are " + join_quoted(valid));
  for (auto it = v.node.begin(); it != v.node.end(); ++it) {
    const SourceLocation key_at = v.source->locate(it->first, at_);
    if (!it->first.IsScalar())
      fail(key_at, "a key of " + what() + " is not a plain word; write 'key: value'");
    const std::string key = it->first.Scalar();
    if (key == "<<")
      fail(key_at, "YAML merge keys ('<<: *anchor') are not read in " + what() +
                       "; write the keys out (a whole aliased value, 'key: *anchor', is read)");
    if (std::find(valid.begin(), valid.end(), key) == valid.end())
      fail(key_at, "unknown key " + quote(key) + " in " + what() + "; " + suggestion(key, valid, "keys"));
    if (const auto previous = entries_.find(key); previous != entries_.end())
      fail(key_at, "key " + quote(key) + " appears twice in " + what() + " (first on line " +
                       std::to_string(previous->second.key_at.line) + "); keep one");
    // A null value ("key:" with nothing) carries the next line's mark; the key's mark is where it is.
    const SourceLocation value_at = v.source->locate(it->second, key_at, !it->second.IsNull());
    entries_.emplace(key, Entry{key_at, Value{v.source, it->second, value_at, child_path(key)}});
  }
}

std::optional<Value> Map::find(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return get(key);
}

const Value& Map::require(const std::string& key, const std::string& example) const {
  if (!has(key)) fail(at_, what() + " has no " + quote(key) + ", which is required; add e.g. " + example);
  return get(key);
}

namespace {

// Where the innermost '[' or '{' that is still open at yaml-cpp's mark was opened, or nothing. yaml-cpp
// reports an unclosed flow collection ("end of sequence flow not found") at the token that should have been
// ',' or ']', usually on a later line; the user needs the line of the bracket. The scan skips comments and
// quoted text, and takes a bracket outside any flow collection as an opener only where a value can begin
// (at the start of a line or after ': ', '- ', '? '), so that '[' inside plain text ("note: see [1") is not
// counted. Block scalars ('|', '>') are not recognized: a bracket at the start of one of their lines would be
// taken for an opener, which is why the caller checks the bracket's kind and still names yaml-cpp's place.
std::optional<std::pair<SourceLocation, char>> unclosed_flow_opener(const std::string& text,
                                                                    const YAML::Mark& mark,
                                                                    const std::string& file) {
  struct Open {
    int line, column;
    char bracket;
  };
  std::vector<Open> open;
  int line = 0, column = 0;
  char quote = 0;     // the quote of the quoted scalar we are in, or 0
  char previous = 0;  // the last character on this line that is not a space (0: none yet)
  bool space = true;  // the character before is a space, a tab or the start of the line
  // A quoted scalar or a flow collection may begin here: at the start of a line, after ': ', '- ' or '? '
  // outside flow collections, and after '[', '{', ',', ':' or '?' inside one.
  const auto value_can_begin = [&] {
    if (previous == 0) return true;
    if (open.empty()) return space && std::strchr(":-?", previous) != nullptr;
    return std::strchr("[{,:?", previous) != nullptr;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (line > mark.line || (line == mark.line && column >= mark.column)) break;
    const char c = text[i];
    if (c == '\n') {
      ++line, column = 0, previous = 0, space = true;
      continue;
    }
    if (quote == '"' && c == '\\') {  // an escape: skip the escaped character (not a newline)
      if (i + 1 < text.size() && text[i + 1] != '\n') ++i, ++column;
    } else if (quote == '\'' && c == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
      ++i, ++column;  // '' is a quote inside single quotes
    } else if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '#' && space) {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
      continue;  // the newline resets the line's state
    } else if ((c == '"' || c == '\'') && value_can_begin()) {
      quote = c;
    } else if ((c == '[' || c == '{') && (!open.empty() || value_can_begin())) {
      open.push_back({line, column, c});
    } else if ((c == ']' || c == '}') && !open.empty() && open.back().bracket == (c == ']' ? '[' : '{')) {
      open.pop_back();
    }
    if (c != ' ' && c != '\t') previous = c;
    space = c == ' ' || c == '\t';
    ++column;
  }
  if (open.empty()) return std::nullopt;
  return std::make_pair(SourceLocation{file, open.back().line + 1, open.back().column + 1},
                        open.back().bracket);
}

// The place of the first tab in the indentation (the blanks that start a line) of the lines up to
// `last_line` (0-based), or nothing.
std::optional<SourceLocation> indenting_tab(const std::string& text, int last_line, const std::string& file) {
  int line = 0, column = 0;
  bool indenting = true;
  for (const char c : text) {
    if (line > last_line) break;
    if (c == '\n') {
      ++line, column = 0, indenting = true;
      continue;
    }
    if (indenting && c == '\t') return SourceLocation{file, line + 1, column + 1};
    if (c != ' ') indenting = false;
    ++column;
  }
  return std::nullopt;
}

}  // namespace

std::string read_yaml_text(const std::string& path, const std::string& kind) {
  require_regular_file(path, kind + " file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open " + kind + " file '" + path + "': check its permissions");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

YAML::Node parse_yaml_document(const std::string& text, const std::string& file, const std::string& kind) {
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    const SourceLocation where{file, e.mark.line + 1, e.mark.column + 1};
    // An unclosed '[' or '{': named where it opened, not where yaml-cpp noticed (often a later line).
    const bool sequence = e.msg == YAML::ErrorMsg::END_OF_SEQ_FLOW;
    if (sequence || e.msg == YAML::ErrorMsg::END_OF_MAP_FLOW)
      if (const auto opener = unclosed_flow_opener(text, e.mark, file);
          opener && opener->second == (sequence ? '[' : '{'))
        fail(opener->first, std::string("YAML syntax error: this '") + opener->second + "' is not closed (" +
                                e.msg + ", noticed at line " + std::to_string(where.line) + ", column " +
                                std::to_string(where.column) + "); add the '" + (sequence ? ']' : '}') +
                                "' that closes it, and check the commas between its entries");
    // A tab in the indentation (an editor's, or text pasted from elsewhere) is no YAML; yaml-cpp reports
    // whatever it makes of the line after it ("illegal map value"), which does not say so.
    if (const auto tab = indenting_tab(text, e.mark.line, file))
      fail(*tab, "YAML syntax error: this line is indented with a tab, which YAML does not allow (" + e.msg +
                     ", noticed at line " + std::to_string(where.line) + ", column " +
                     std::to_string(where.column) + "); indent with spaces");
    fail(where,
         "YAML syntax error: " + e.msg + "; check the indentation, colons and brackets near this place");
  }
  // Two scenarios (or studies) pasted into one file: the second would be ignored without a word.
  for (size_t i = 1; i < documents.size(); ++i)
    if (!documents[i].IsNull())
      fail({file, documents[i].Mark().line + 1, 1},
           "a second YAML document starts here (after a '---' or '...' line); a " + kind +
               " file holds one " + kind + ": put each " + kind + " in its own file");
  return documents.empty() ? YAML::Node() : documents.front();
}

}  // namespace hexbite::yaml_input
