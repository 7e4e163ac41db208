# The operator in the loop (issue: operator): scripted_operator answering prompts by rule, and
# riggerctl's operator and jog commands, as real processes against this test's own participant.
if(TARGET scripted_operator AND TARGET riggerctl)
  rigger_add_test(rigger_operator_test
    SOURCES operator_test.cpp
    DEPS rigger_test_harness rigger_operator_protocol nlohmann_json::nlohmann_json LABEL integration TIMEOUT 60)
  add_dependencies(rigger_operator_test scripted_operator riggerctl)
endif()
# The shipped scripted operator answering the real task controller's OperatorDecision.
if(TARGET scripted_operator AND TARGET task_controller AND TARGET scripted_executor)
  rigger_add_test(rigger_operator_task_test
    SOURCES operator_task_test.cpp
    DEPS rigger_test_harness rigger_task_controller_core LABEL integration TIMEOUT 90)
  add_dependencies(rigger_operator_task_test scripted_operator task_controller scripted_executor)
endif()
