# Localize and Screw on real processes: world_model and the shipped perception-skills and
# operator-skills executors, the test acting as controller, vision tracker and operator.
if(TARGET skill_executor AND TARGET world_model)
  rigger_add_test(rigger_skills_cell_test
    SOURCES skills_cell_test.cpp
    DEPS rigger_test_harness rigger_world_client rigger_operator_ui Eigen3::Eigen nlohmann_json::nlohmann_json LABEL integration TIMEOUT 120)
  add_dependencies(rigger_skills_cell_test skill_executor world_model)
endif()
