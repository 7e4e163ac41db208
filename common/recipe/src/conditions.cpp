#include "rigger/recipe/conditions.hpp"

namespace rigger::recipe {

const nlohmann::json& controller_conditions_json() {
  static const nlohmann::json library = nlohmann::json::parse(R"json({
    "library_version": 1,
    "skills": [
      {
        "name": "ObjectLocalized", "kind": "condition",
        "description": "True when the world model holds a pose of the object younger than max_age_s.",
        "params": [
          { "name": "object", "type": "string", "min": 1, "description": "World-model id of the object." },
          { "name": "max_age_s", "type": "number", "unit": "s", "min": 0, "max": 3600, "default": 5,
            "description": "Oldest pose that counts as localized." }
        ],
        "postconditions": ["localized($object)"]
      }
    ]
  })json");
  return library;
}

}  // namespace rigger::recipe
