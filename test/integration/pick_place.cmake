# Pick and Place in physics (issue 18): recipes/examples/pick_and_place.json on every real process of the
# cell, the part's final true pose checked against the recipe's place pose. Real time (about a minute); it
# runs alone, as the scenario tests do, since the physics, the camera and the tracker need the cores.
set(_pick_place_services cell_sim crane_gateway world_model vision_tracker admittance_control monitor_host
    skill_executor task_controller scripted_operator)
rigger_targets_exist(_pick_place_ready ${_pick_place_services})
if(_pick_place_ready)
  rigger_add_test(rigger_pick_place_cell_test
    SOURCES pick_place_cell_test.cpp
    DEPS rigger_test_harness rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 420 RUN_SERIAL)
  add_dependencies(rigger_pick_place_cell_test ${_pick_place_services})
endif()
