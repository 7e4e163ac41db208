# The task controller with real peers (controller_*_test.cpp; shared fixture controller_test_support.hpp).
if(TARGET task_controller AND TARGET scripted_executor AND TARGET riggerctl)
  # riggerctl run/status/tree/skills/cancel/log against a live controller and scripted executor.
  rigger_add_test(rigger_controller_riggerctl_test
    SOURCES controller_riggerctl_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol LABEL integration TIMEOUT 120)
  add_dependencies(rigger_controller_riggerctl_test task_controller scripted_executor riggerctl)
endif()
if(TARGET task_controller AND TARGET scripted_executor AND TARGET riggerctl AND TARGET world_model)
  # Resume after a crash: controller SIGKILLed mid-task, restarted, riggerctl resume, the operator's answer;
  # with the real world model, a load moved while the controller was down is localized again.
  rigger_add_test(rigger_controller_resume_test
    SOURCES controller_resume_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol rigger_world_client
    LABEL integration TIMEOUT 300)
  add_dependencies(rigger_controller_resume_test task_controller scripted_executor riggerctl world_model)
endif()
if(TARGET task_controller AND TARGET scripted_executor)
  # PAUSE/RESUME, CANCEL, OperatorDecision, stop-timeout escalation.
  rigger_add_test(rigger_controller_lifecycle_test
    SOURCES controller_lifecycle_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol rigger_safety LABEL integration TIMEOUT 120)
  add_dependencies(rigger_controller_lifecycle_test task_controller scripted_executor)
endif()
if(TARGET task_controller AND TARGET world_model AND TARGET rigger_world_client)
  # A Condition reads the world model and follows it as it changes.
  rigger_add_test(rigger_controller_world_test
    SOURCES controller_world_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol rigger_world_client LABEL integration TIMEOUT 120)
  add_dependencies(rigger_controller_world_test task_controller world_model)
endif()
if(TARGET task_controller AND TARGET scripted_executor AND TARGET monitor_host)
  # A real ForceMonitor (monitor_host) in a Parallel with a scripted skill.
  rigger_add_test(rigger_controller_monitor_test
    SOURCES controller_monitor_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core rigger_operator_protocol LABEL integration TIMEOUT 120)
  add_dependencies(rigger_controller_monitor_test task_controller scripted_executor monitor_host)
endif()
