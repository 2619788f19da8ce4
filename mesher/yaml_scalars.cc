#include "mesher/yaml_scalars.h"

#include <cmath>

#include "common/suggestion.h"

namespace hexbite {

bool is_quoted(const YAML::Node& node) {
  return node.IsScalar() && (node.Tag() == "!" || node.Tag() == "tag:yaml.org,2002:str");
}

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  if (is_quoted(node)) return "the quoted text \"" + node.Scalar() + "\"";
  return quote(node.Scalar());
}

namespace {

std::optional<double> finite_scalar(const YAML::Node& node) {
  double x = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, x) || !std::isfinite(x)) return std::nullopt;
  return x;
}

}  // namespace

std::optional<double> plain_number(const YAML::Node& node) {
  if (is_quoted(node)) return std::nullopt;
  return finite_scalar(node);
}

std::string number_expected(const YAML::Node& node) {
  return "found " + describe(node) +
         (is_quoted(node) && finite_scalar(node)
              ? "; write it as a plain number, without quotes: " + node.Scalar()
              : "; write a plain finite number such as 2.5");
}

}  // namespace hexbite
