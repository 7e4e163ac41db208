# The gripper skills (AttachRobotToLoad, Release) on real processes: cell_sim + world_model +
# skill_executor, the test acting as the controller.
if(TARGET skill_executor AND TARGET cell_sim AND TARGET world_model)
  rigger_add_test(rigger_skills_robot_test
    SOURCES skills_robot_test.cpp
    DEPS rigger_test_harness rigger_world_client Eigen3::Eigen nlohmann_json::nlohmann_json LABEL integration TIMEOUT 300)
  add_dependencies(rigger_skills_robot_test skill_executor cell_sim world_model)
endif()
# With the crane gateway built too, a test with the crane's health in the loop (CRANE_FAULT refusal).
if(TARGET rigger_skills_robot_test AND TARGET crane_gateway)
  target_compile_definitions(rigger_skills_robot_test PRIVATE RIGGER_WITH_CRANE_GATEWAY=1)
  add_dependencies(rigger_skills_robot_test crane_gateway)
endif()
# A skill written outside the tree (examples/skill_plugin) against the installed skill SDK: installed,
# built with find_package(rigger), unit-tested, and run by the real controller on the physics arm.
if(TARGET rigger_skill_sdk AND TARGET cell_sim AND TARGET task_controller)
  rigger_add_test(rigger_skill_sdk_plugin_test
    SOURCES skill_sdk_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 420)
  target_compile_definitions(rigger_skill_sdk_plugin_test PRIVATE RIGGER_CMAKE_COMMAND="${CMAKE_COMMAND}")
  add_dependencies(rigger_skill_sdk_plugin_test cell_sim task_controller rigger_skill_sdk)
endif()
