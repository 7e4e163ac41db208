# Localize and Screw on real processes: world_model and the shipped perception-skills and
# operator-skills executors, the test acting as controller, vision tracker and operator.
if(TARGET skill_executor AND TARGET world_model)
  rigger_add_test(rigger_skills_cell_test
    SOURCES skills_cell_test.cpp
    DEPS rigger_test_harness rigger_world_client rigger_operator_protocol Eigen3::Eigen nlohmann_json::nlohmann_json LABEL integration TIMEOUT 120)
  add_dependencies(rigger_skills_cell_test skill_executor world_model)
endif()
# A PAUSE that holds motion: MoveTo on the physics arm through the real controller, paused
# mid-motion (the arm below 1 mm/s and staying there), resumed to SUCCEEDED (about 15 s).
if(TARGET cell_sim AND TARGET skill_executor AND TARGET task_controller AND TARGET riggerctl)
  rigger_add_test(rigger_pause_cell_test
    SOURCES pause_cell_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 90 RUN_SERIAL)
  add_dependencies(rigger_pause_cell_test cell_sim skill_executor task_controller riggerctl)
endif()
