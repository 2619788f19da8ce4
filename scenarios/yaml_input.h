// The YAML layer under scenario and study files (scenarios/scenario.h, scenarios/study.h): reading one YAML
// document with its syntax errors named where the user must look, knowing where every node was written, and
// strict typed access whose errors read "FILE:LINE:COLUMN: what is wrong; what to do" (InputError).
//
// Why a Source and not just the file name: a study's variant is its base scenario's tree with the study's
// `set` values grafted in, so one tree holds nodes of two files. A value that the study changed must be
// reported at the study's line, everything else at the base scenario's, and a relative path resolves against
// the folder of the file it was written in. Internal to the scenarios library.
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/suggestion.h"
#include "mesher/yaml_scalars.h"
#include "scenarios/scenario.h"

namespace hexbite::yaml_input {

// A node written in another file than the rest of its tree (a study's `set` value, each node inside it, and
// the key that a `set` added), with its place there.
struct GraftedNode {
  YAML::Node node;
  SourceLocation at;
  std::filesystem::path folder;  // relative paths written in it resolve against this folder
};

// Where the nodes of one YAML tree were written.
struct Source {
  std::string file;              // as given: every node that is not grafted was written there
  std::filesystem::path folder;  // relative paths written in `file` resolve against it
  std::string note;              // SourceLocation::note of the places in `file`
  std::vector<GraftedNode> grafted;

  // The place of `node`: its grafted place, else its mark in `file`; `fallback` for a node that no file
  // holds, and for an ungrafted one when `use_mark` is false (a null value carries the next line's mark).
  // Linear in the grafted nodes, which are a study's few values.
  SourceLocation locate(const YAML::Node& node, const SourceLocation& fallback, bool use_mark = true) const;
  // The folder that a relative path written in `node` resolves against.
  std::filesystem::path folder_of(const YAML::Node& node) const;
};

[[noreturn]] void fail(const SourceLocation& where, const std::string& message);

// A YAML node with its tree's Source, where it was written and its path in the document
// ("muscles[2].activation").
struct Value {
  const Source* source;
  YAML::Node node;
  SourceLocation at;
  std::string path;
};

// A whole number as YAML 1.2 reads it, in decimal: "04000" is 4000 (yaml-cpp's own conversion reads it as
// octal, 2048, without a word), and "2e3" or "4000.0" are whole numbers too. Hexadecimal and octal
// ("0x10", "0o10") are not: nobody writes a mesh size that way on purpose. False for anything else
// (quoted text, fractions, lists, numbers beyond +-2^53).
bool decimal_whole_number(const YAML::Node& node, long long* value);

// What to write for free text (a description) that came as a list or a mapping.
inline const std::string kTextHint =
    "write it as one line of text, in quotes if it holds a colon or starts with [ or {";

// Non-empty text; `hint` says what to write instead of a list, a mapping or nothing.
std::string to_string(const Value& v, const std::string& hint = "write a word such as left_condyle");
// to_string() for a name (of the scenario, a region, muscle, support, probe or study): names go into comment
// and heading lines of the files written (model.inp, reports), so a control character (a newline, a tab)
// is refused at its line: "incisal\n*HEADING" made the rest of the name a CalculiX keyword line.
std::string to_name(const Value& v, const std::string& hint = "write a word such as left_condyle");
std::vector<Value> to_list(const Value& v);  // a list (null reads as an empty one)

// A mapping whose keys are checked against the valid ones on construction (unknown and repeated keys are
// errors at the key, the closest valid key suggested), with access by key.
class Map {
 public:
  // `document` names the whole file's mapping in messages ("unknown key 'x' in the scenario").
  Map(const Value& v, std::vector<std::string> valid, std::string document = "the scenario");

  bool has(const std::string& key) const { return entries_.count(key) > 0; }
  const Value& get(const std::string& key) const { return entries_.at(key).value; }
  const SourceLocation& key_at(const std::string& key) const { return entries_.at(key).key_at; }
  std::optional<Value> find(const std::string& key) const;
  const Value& require(const std::string& key, const std::string& example) const;
  const SourceLocation& at() const { return at_; }
  std::string what() const { return path_.empty() ? document_ : path_; }

 private:
  struct Entry {
    SourceLocation key_at;
    Value value;
  };
  std::string child_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  SourceLocation at_;
  std::string path_;
  std::string document_;
  std::map<std::string, Entry> entries_;
};

// The text of a YAML file; InputError "cannot read <kind> file ..." when it cannot be read.
std::string read_yaml_text(const std::string& path, const std::string& kind);

// The one YAML document of `text`, read from `file` (null for an empty file). Syntax errors are
// InputErrors at their place (an unclosed '[' or '{' at the bracket, a tab in the indentation at the tab),
// and so is a second document: one file holds one `kind` ("scenario", "study").
YAML::Node parse_yaml_document(const std::string& text, const std::string& file, const std::string& kind);

}  // namespace hexbite::yaml_input
