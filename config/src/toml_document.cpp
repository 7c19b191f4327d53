#include "tomorig/config/toml_document.h"

#include <toml++/toml.h>

namespace tomorig::config {
namespace {

const toml::node* as_node(const void* p) { return static_cast<const toml::node*>(p); }

template <typename T>
std::optional<T> value_of(const void* p) {
  if (!p) return std::nullopt;
  const auto v = as_node(p)->value<T>();
  if (!v) return std::nullopt;
  return T(*v);
}

}  // namespace

bool TomlNode::is_table() const { return node_ && as_node(node_)->is_table(); }
bool TomlNode::is_array() const { return node_ && as_node(node_)->is_array(); }
bool TomlNode::is_array_of_tables() const { return node_ && as_node(node_)->is_array_of_tables(); }
bool TomlNode::is_number() const { return node_ && as_node(node_)->is_number(); }
bool TomlNode::is_integer() const { return node_ && as_node(node_)->is_integer(); }
bool TomlNode::is_string() const { return node_ && as_node(node_)->is_string(); }
bool TomlNode::is_boolean() const { return node_ && as_node(node_)->is_boolean(); }

int TomlNode::line() const { return node_ ? static_cast<int>(as_node(node_)->source().begin.line) : 0; }

TomlNode TomlNode::operator[](std::string_view key) const {
  const toml::table* t = node_ ? as_node(node_)->as_table() : nullptr;
  return TomlNode(t ? t->get(key) : nullptr);
}

bool TomlNode::contains(std::string_view key) const {
  const toml::table* t = node_ ? as_node(node_)->as_table() : nullptr;
  return t && t->contains(key);
}

std::vector<std::pair<std::string, TomlNode>> TomlNode::entries() const {
  std::vector<std::pair<std::string, TomlNode>> out;
  if (const toml::table* t = node_ ? as_node(node_)->as_table() : nullptr)
    for (const auto& [key, value] : *t) out.emplace_back(std::string(key.str()), TomlNode(&value));
  return out;
}

std::size_t TomlNode::size() const {
  const toml::array* a = node_ ? as_node(node_)->as_array() : nullptr;
  return a ? a->size() : 0;
}

TomlNode TomlNode::operator[](std::size_t index) const {
  const toml::array* a = node_ ? as_node(node_)->as_array() : nullptr;
  return TomlNode(a ? a->get(index) : nullptr);
}

std::optional<double> TomlNode::as_double() const { return value_of<double>(node_); }
std::optional<std::int64_t> TomlNode::as_integer() const { return value_of<std::int64_t>(node_); }
std::optional<bool> TomlNode::as_bool() const { return value_of<bool>(node_); }
std::optional<std::string> TomlNode::as_string() const { return value_of<std::string>(node_); }

struct TomlDocument::Tree {
  toml::table root;
};

TomlDocument::TomlDocument(std::unique_ptr<Tree> tree) : tree_(std::move(tree)) {}
TomlDocument::TomlDocument(TomlDocument&&) noexcept = default;
TomlDocument& TomlDocument::operator=(TomlDocument&&) noexcept = default;
TomlDocument::~TomlDocument() = default;

TomlDocument TomlDocument::parse(std::string_view text, const std::string& source) {
  auto tree = std::make_unique<Tree>();
  try {
    tree->root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw TomlSyntaxError(static_cast<int>(e.source().begin.line), std::string(e.description()));
  }
  return TomlDocument(std::move(tree));
}

TomlDocument TomlDocument::parse_file(const std::filesystem::path& path) {
  auto tree = std::make_unique<Tree>();
  try {
    tree->root = toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    throw TomlSyntaxError(static_cast<int>(e.source().begin.line), std::string(e.description()));
  }
  return TomlDocument(std::move(tree));
}

TomlNode TomlDocument::root() const { return TomlNode(static_cast<const toml::node*>(&tree_->root)); }

}  // namespace tomorig::config
