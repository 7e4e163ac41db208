# A cell the repository does not ship (services/cell_sim/physics/test_support: STEP models written with
# OpenCascade and a cell file of CAD rules around them) on the real processes, each given its path.
set(_generated_cell_services cell_sim world_model cad vision_tracker riggerctl)
rigger_targets_exist(_generated_cell_ready ${_generated_cell_services})
if(_generated_cell_ready AND TARGET rigger_generated_cell AND TARGET rigger_world_client)
  rigger_add_test(rigger_generated_cell_test
    SOURCES generated_cell_test.cpp
    DEPS rigger_test_harness rigger_generated_cell rigger_world_client rigger_world_protocol rigger_skill_protocol rigger_cell_config
         ${OpenCV_LIBS} Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 120)
  target_include_directories(rigger_generated_cell_test SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  add_dependencies(rigger_generated_cell_test ${_generated_cell_services})
endif()
# The scenario's recipe on the generated cell, on every process of the scenario (as rigger_scenario_test).
if(_generated_cell_ready AND _scenario_ready AND TARGET rigger_generated_cell)
  rigger_add_test(rigger_generated_cell_scenario_test
    SOURCES generated_cell_scenario_test.cpp
    DEPS rigger_test_harness rigger_generated_cell rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 420 RUN_SERIAL)
  add_dependencies(rigger_generated_cell_scenario_test ${_scenario_services})
endif()
# STEP models carried with a cell revision over DDS: a part only the applying side has reaches the world
# model, the CAD service and cell_sim, each on a cell folder of its own.
set(_cell_model_services cell_sim world_model cad riggerctl)
rigger_targets_exist(_cell_model_ready ${_cell_model_services})
if(_cell_model_ready AND TARGET rigger_cad_parts)
  rigger_add_test(rigger_cell_model_transport_test
    SOURCES cell_model_transport_test.cpp
    DEPS rigger_test_harness rigger_world_protocol rigger_cad_parts Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 120)
  add_dependencies(rigger_cell_model_transport_test ${_cell_model_services})
endif()
