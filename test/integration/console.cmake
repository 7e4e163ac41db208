# The console in headless chromium (issue 15): the paper's scenario with the screw prompts answered by
# clicks in the operator station. Needs /usr/bin/chromium, node and the npm packages of
# services/console/web (deploy/setup installs them); the test skips itself, saying why, without them.
set(_console_services console cell_sim crane_gateway world_model vision_tracker admittance_control monitor_host
    skill_executor task_controller)
set(_console_ready TRUE)
foreach(t IN LISTS _console_services)
  if(NOT TARGET ${t})
    set(_console_ready FALSE)
  endif()
endforeach()
if(_console_ready)
  rigger_add_test(rigger_console_browser_test
    SOURCES console_browser_test.cpp
    DEPS rigger_test_harness rigger_console_core rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 600 RUN_SERIAL)
  target_include_directories(rigger_console_browser_test PRIVATE ${PROJECT_SOURCE_DIR}/services/console/src)
  add_dependencies(rigger_console_browser_test ${_console_services})
endif()
