# The cell over three hosts (docs/deploy.md): network namespaces made by deploy/lab-hosts, rigger-compose on
# each, the scenario with a link cut. Needs root; real time physics: alone.
set(_multi_host_targets cell_sim crane_gateway world_model cad vision_tracker admittance_control monitor_host
    skill_executor task_controller scripted_operator console riggerctl rigger-compose)
rigger_targets_exist(_multi_host_ready ${_multi_host_targets})
if(_multi_host_ready)
  # The scenario over three hosts with a link cut during the insertion (about 60 s), asserting the stop
  # within the lease + 350 ms and the rest of the task's success afterwards.
  rigger_add_test(rigger_multi_host_cut_test
    SOURCES multi_host_cut_test.cpp
    DEPS rigger_test_harness rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 600 RUN_SERIAL)
  add_dependencies(rigger_multi_host_cut_test ${_multi_host_targets})
endif()
