#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include "rigger/recipe/recipe_schema.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/skill/json_text.hpp"

namespace rigger::recipe {
namespace {

using Json = nlohmann::json;

bool starts_with(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }

// valijson reports an error and then, for every enclosing level, a wrapper saying that level
// failed too. The wrappers add nothing but noise for recipe authors.
bool is_wrapper(const std::string& description) {
  return starts_with(description, "Failed to validate against child schema #") ||
         starts_with(description, "Failed to validate against schema associated with property name") ||
         starts_with(description, "Failed to validate item #") ||
         starts_with(description, "Failed to validate against a conditional schema") ||
         starts_with(description, "Failed to validate against additional properties schema") ||
         starts_with(description, "Failed to validate against schema associated with pattern");
}

// valijson's context is {"<root>", "[key]", "[0]", …}.
std::vector<std::string> tokens_of(const std::vector<std::string>& context) {
  std::vector<std::string> tokens;
  for (std::size_t i = 1; i < context.size(); ++i) {
    const std::string& t = context[i];
    tokens.push_back(t.size() >= 2 && t.front() == '[' && t.back() == ']' ? t.substr(1, t.size() - 2) : t);
  }
  return tokens;
}

std::string pointer_of(const std::vector<std::string>& tokens) {
  std::string out;
  for (const auto& t : tokens) {
    out += "/" + rigger::escape_pointer_token(t);
  }
  return out;
}

bool is_index(const std::string& token) {
  return !token.empty() && token.find_first_not_of("0123456789") == std::string::npos;
}

// The value at `tokens` in `document`, or nullptr when absent.
const Json* lookup(const Json& document, const std::vector<std::string>& tokens) {
  const Json* at = &document;
  for (const auto& t : tokens) {
    if (at->is_object()) {
      const auto it = at->find(t);
      if (it == at->end()) {
        return nullptr;
      }
      at = &*it;
    } else if (at->is_array() && is_index(t) && t.size() < 10 && std::stoul(t) < at->size()) {
      at = &(*at)[std::stoul(t)];
    } else {
      return nullptr;
    }
  }
  return at;
}

std::string quoted(const std::string& text) { return "\"" + text + "\""; }

}  // namespace

struct SchemaValidator::Impl {
  valijson::Schema schema;
  /// Property name → what its value must be; "name[]" → what each item of that array must be.
  std::map<std::string, std::string> expectations;
  /// Allowed property names: per node type, "" for the document, "option" for OperatorDecision options.
  std::map<std::string, std::vector<std::string>> properties;
  std::vector<std::string> node_types;

  std::string describe(const Json& sub) const {
    if (!sub.is_object()) {
      return "";
    }
    if (sub.contains("$ref")) {
      if (sub["$ref"] == "#/definitions/node") {
        std::string types;
        for (std::size_t i = 0; i < node_types.size(); ++i) {
          types += (i == 0 ? "" : ", ") + node_types[i];
        }
        return "a node object with \"type\" one of " + types;
      }
      return "";
    }
    if (sub.contains("const")) {
      return "the value " + sub["const"].dump();
    }
    if (sub.contains("enum") && sub["enum"].is_array()) {
      std::string values;
      for (std::size_t i = 0; i < sub["enum"].size(); ++i) {
        values += (i == 0 ? "" : ", ") + sub["enum"][i].dump();
      }
      return "one of " + values;
    }
    const std::string type = sub.value("type", "");
    if (type == "integer" || type == "number") {
      std::string text = type == "integer" ? "an integer" : "a number";
      std::vector<std::string> bounds;
      if (sub.contains("minimum")) {
        bounds.push_back(">= " + skill::format_number(sub["minimum"].get<double>()));
      }
      if (sub.contains("exclusiveMinimum")) {
        bounds.push_back("> " + skill::format_number(sub["exclusiveMinimum"].get<double>()));
      }
      if (sub.contains("maximum")) {
        bounds.push_back("<= " + skill::format_number(sub["maximum"].get<double>()));
      }
      for (std::size_t i = 0; i < bounds.size(); ++i) {
        text += (i == 0 ? " " : " and ") + bounds[i];
      }
      return text;
    }
    if (type == "string") {
      std::string text = sub.value("minLength", 0) > 0 ? "a non-empty string" : "a string";
      if (sub.contains("maxLength")) {
        text += " of at most " + std::to_string(sub["maxLength"].get<int>()) + " characters";
      }
      if (sub.contains("pattern")) {
        text += " matching " + sub["pattern"].get<std::string>();
      }
      return text;
    }
    if (type == "array") {
      std::string text = "an array";
      const int min_items = sub.value("minItems", 0);
      if (sub.contains("maxItems")) {
        text += " of " + std::to_string(min_items) + " to " + std::to_string(sub["maxItems"].get<int>()) + " items";
      } else if (min_items > 0) {
        text += " of at least " + std::to_string(min_items) + " items";
      }
      return text;
    }
    if (type == "object") {
      return "an object";
    }
    return "";
  }

  void learn_properties(const std::string& owner, const Json& object_schema) {
    if (!object_schema.contains("properties")) {
      return;
    }
    auto& names = properties[owner];
    for (const auto& [name, sub] : object_schema["properties"].items()) {
      names.push_back(name);
      const std::string text = describe(sub);
      if (!text.empty() && !expectations.count(name)) {
        expectations[name] = text;
      }
      if (sub.contains("items")) {
        const std::string item = describe(sub["items"]);
        if (!item.empty() && !expectations.count(name + "[]")) {
          expectations[name + "[]"] = item;
        }
        if (sub["items"].is_object() && sub["items"].contains("properties")) {
          learn_properties(name == "options" ? "option" : name + "[]", sub["items"]);
        }
      }
    }
  }

  void learn(const Json& schema_json) {
    if (schema_json.contains("definitions")) {
      const Json& defs = schema_json["definitions"];
      if (defs.contains("node") && defs["node"].contains("properties") &&
          defs["node"]["properties"].contains("type") && defs["node"]["properties"]["type"].contains("enum")) {
        for (const auto& t : defs["node"]["properties"]["type"]["enum"]) {
          node_types.push_back(t.get<std::string>());
        }
      }
      // The node definition first: its "type" carries the enum of node types.
      if (defs.contains("node")) {
        learn_properties("node", defs["node"]);
      }
      for (const auto& [name, def] : defs.items()) {
        if (name != "node") {
          learn_properties(name, def);
        }
      }
    }
    learn_properties("", schema_json);
  }

  std::vector<std::string> allowed_properties(const Json& document, const std::vector<std::string>& object_tokens) const {
    std::string owner;
    if (!object_tokens.empty()) {
      const Json* object = lookup(document, object_tokens);
      if (object != nullptr && object->is_object() && object->contains("type") && (*object)["type"].is_string() &&
          properties.count((*object)["type"].get<std::string>())) {
        owner = (*object)["type"].get<std::string>();
      } else if (object_tokens.size() >= 2 && object_tokens[object_tokens.size() - 2] == "options") {
        owner = "option";
      } else {
        return {};
      }
    }
    const auto it = properties.find(owner);
    return it == properties.end() ? std::vector<std::string>{} : it->second;
  }

  skill::ModelError explain(const Json& document, const valijson::ValidationResults::Error& error) const {
    std::vector<std::string> tokens = tokens_of(error.context);
    const std::string& description = error.description;
    if (starts_with(description, "Missing required property '")) {
      const auto begin = description.find('\'') + 1;
      const std::string name = description.substr(begin, description.rfind('\'') - begin);
      const auto it = expectations.find(name);
      return {pointer_of(tokens), "missing required property " + quoted(name) +
                                      (it == expectations.end() ? "" : ": expected " + it->second)};
    }
    if (starts_with(description, "Object contains a property that could not be validated")) {
      const auto end = description.rfind('\'');
      const auto begin = description.rfind('\'', end - 1) + 1;
      const std::string name = description.substr(begin, end - begin);
      const auto allowed = allowed_properties(document, tokens);
      std::string message = "unknown property " + quoted(name);
      if (!allowed.empty()) {
        message += "; expected one of ";
        for (std::size_t i = 0; i < allowed.size(); ++i) {
          message += (i == 0 ? "" : ", ") + quoted(allowed[i]);
        }
      }
      tokens.push_back(name);
      return {pointer_of(tokens), message};
    }
    std::string key;
    if (!tokens.empty()) {
      key = tokens.back();
      if (is_index(key) && tokens.size() >= 2) {
        key = tokens[tokens.size() - 2] + "[]";
      }
    }
    const auto it = expectations.find(key);
    const Json* value = lookup(document, tokens);
    if (tokens.empty() && (document.is_object() == false)) {
      return {"", "expected a recipe object {\"recipe_version\": 1, \"task_id\", \"root\"}, got " +
                      skill::describe_json(document)};
    }
    if (it == expectations.end() || value == nullptr) {
      return {pointer_of(tokens), description};
    }
    return {pointer_of(tokens), "expected " + it->second + ", got " + skill::describe_json(*value)};
  }
};

SchemaValidator::SchemaValidator(const Json& schema) : impl_(std::make_unique<Impl>()) {
  try {
    valijson::SchemaParser parser(valijson::SchemaParser::kDraft7);
    valijson::adapters::NlohmannJsonAdapter adapter(schema);
    parser.populateSchema(adapter, impl_->schema);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("recipe schema does not compile: ") + e.what());
  }
  impl_->learn(schema);
}

SchemaValidator::~SchemaValidator() = default;

std::vector<skill::ModelError> SchemaValidator::validate(const Json& document) const {
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(document);
  std::vector<skill::ModelError> errors;
  if (validator.validate(impl_->schema, target, &results)) {
    return errors;
  }
  std::set<std::pair<std::string, std::string>> seen;
  valijson::ValidationResults::Error error;
  while (results.popError(error)) {
    if (is_wrapper(error.description)) {
      continue;
    }
    auto explained = impl_->explain(document, error);
    if (seen.emplace(explained.pointer, explained.message).second) {
      errors.push_back(std::move(explained));
    }
  }
  if (errors.empty()) {
    errors.push_back({"", "does not match the recipe schema"});
  }
  return errors;
}

const SchemaValidator& SchemaValidator::recipe() {
  static const SchemaValidator kRecipe(Json::parse(recipe_schema_text()));
  return kRecipe;
}

}  // namespace rigger::recipe
