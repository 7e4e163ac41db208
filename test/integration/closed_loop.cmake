# Closed loop in the simulated cell with real processes (admittance_control acceptance):
# cell_sim + crane_gateway + vision_tracker + admittance_control, real time.
if(TARGET admittance_control AND TARGET cell_sim AND TARGET crane_gateway AND TARGET vision_tracker)
  rigger_add_test(rigger_closed_loop_test
    SOURCES closed_loop_test.cpp
    DEPS rigger_test_harness rigger_admittance_control_core rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 600)
  add_dependencies(rigger_closed_loop_test admittance_control cell_sim crane_gateway vision_tracker)
  if(TARGET echo)  # the stand-in commander that KilledCommanderStopsTheInsertion SIGKILLs
    add_dependencies(rigger_closed_loop_test echo)
  endif()
endif()
