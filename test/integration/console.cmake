# The console in headless chromium. Each test needs /usr/bin/chromium, node and the npm packages of
# services/console/web (deploy/setup installs them); it skips itself, saying why, without them.
# A browser test is added only when every service it starts is configured.
function(rigger_console_browser_test name source)
  foreach(t IN LISTS ARGN)
    if(NOT TARGET ${t})
      return()
    endif()
  endforeach()
  rigger_add_test(${name}
    SOURCES ${source}
    DEPS rigger_test_harness rigger_console_core rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 600 RUN_SERIAL)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/services/console/src)
  add_dependencies(${name} ${ARGN})
endfunction()

# The console: the paper's scenario with the screw prompts answered by clicks in the operator station.
rigger_console_browser_test(rigger_console_browser_test console_browser_test.cpp
  console cad cell_sim crane_gateway world_model vision_tracker admittance_control monitor_host skill_executor task_controller)
# The planner: the CAD service, world model, controller, scripted executors with the real skill
# library and the console; the tree built by clicks, holes picked in the 3D view.
rigger_console_browser_test(rigger_planner_browser_test planner_browser_test.cpp
  console cad world_model scripted_executor task_controller)
if(TARGET rigger_planner_browser_test)
  # The import's STEP file the repository does not ship: the generated cell's flange (OpenCascade).
  target_link_libraries(rigger_planner_browser_test PRIVATE rigger_generated_cell rigger_cad_parts)
endif()
# The planner's acceptance: the paper's task (recipes/crane_insert.json) built in the planner by clicks and
# CAD picks only, compared with the shipped recipe; the same services as the planner test.
# The second test also rehearses the planned task on the full simulated cell of a second domain.
rigger_console_browser_test(rigger_planner_paper_task_test planner_paper_task_test.cpp
  console cad world_model scripted_executor task_controller cell_sim crane_gateway vision_tracker
  admittance_control monitor_host skill_executor scripted_operator)
# The planner, rehearse then publish: crane_insert.json rehearsed from the planner on the full simulated cell
# (real physics) of a second DDS domain, followed live in the page; nothing reaches the console's own cell
# (a controller with scripted executors). Runs the cell in real time (about 2-3 minutes).
rigger_console_browser_test(rigger_rehearsal_browser_test rehearsal_browser_test.cpp
  console cell_sim crane_gateway world_model vision_tracker admittance_control monitor_host skill_executor
  task_controller scripted_operator scripted_executor)
# Rehearse with no rehearsal cell running: the console starts it (a controller and scripted executors run
# by a shell script on a second domain), the page says so and shows the run; idle, the console stops it.
rigger_console_browser_test(rigger_rehearsal_on_demand_browser_test rehearsal_on_demand_browser_test.cpp
  console cad world_model scripted_executor task_controller)
# A cell the repository does not ship (rigger/sim/generated_cell.hpp) in the console: its six objects in
# the Planner from their STEP models, a part picked by a click, a flange hole on the operator station and
# a cell revision from the Tasks page against the real world model.
if(TARGET rigger_generated_cell AND TARGET rigger_world_client)
  rigger_console_browser_test(rigger_generated_cell_browser_test generated_cell_browser_test.cpp
    console cad world_model scripted_executor)
  if(TARGET rigger_generated_cell_browser_test)
    target_link_libraries(rigger_generated_cell_browser_test PRIVATE rigger_generated_cell rigger_world_client
                          rigger_operator_protocol)
  endif()
endif()
# A new crane load rehearsed in physics: the console's rehearsal link starts the rehearsal cell (a world
# model, cell_sim and a controller run by a shell script) on the cell's revision, and starts it again on a
# revision that puts the generated cell's L bracket on the rope (no browser).
if(TARGET rigger_generated_cell AND TARGET rigger_console_core AND TARGET cell_sim AND TARGET world_model
   AND TARGET task_controller)
  rigger_add_test(rigger_rehearsal_new_load_test
    SOURCES rehearsal_new_load_test.cpp
    DEPS rigger_test_harness rigger_console_core rigger_generated_cell rigger_sha256 nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 600 RUN_SERIAL)
  if(TARGET rigger_rehearsal_new_load_test)
    target_include_directories(rigger_rehearsal_new_load_test PRIVATE ${PROJECT_SOURCE_DIR}/services/console/src)
    add_dependencies(rigger_rehearsal_new_load_test cell_sim world_model task_controller)
  endif()
endif()
# A new product: two STEP files written in the test (rigger::sim::write_new_product) imported, placed,
# declared and programmed in the Planner by clicks only, validated, exported, replayed to the same bytes,
# rehearsed in physics on the rehearsal cell the console starts on the revision as deployed (rigger-compose
# supervise on deploy/compose.yaml), and published on the console's cell, made the simulated cell (the
# scenario harness) once the rehearsal cell stopped.
rigger_console_browser_test(rigger_planner_new_product_test planner_new_product_test.cpp
  console cad world_model scripted_executor task_controller rigger-compose cell_sim crane_gateway vision_tracker
  admittance_control monitor_host skill_executor scripted_operator)
if(TARGET rigger_planner_new_product_test)
  target_link_libraries(rigger_planner_new_product_test PRIVATE rigger_generated_cell)
endif()
