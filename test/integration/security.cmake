# DDS Security (docs/security.md): a PKI made by deploy/security/make-pki, a secured cell
# brought up by `rigger-compose up --secure`, intruders (rigger_security_probe) and a permitted riggerctl.
if(TARGET task_controller AND TARGET scripted_executor AND TARGET riggerctl AND TARGET rigger-compose
   AND TARGET rigger-topic-catalog)
  rigger_add_executable(rigger_security_probe SOURCES security/security_probe.cpp DEPS rigger_dds NOT_INSTALLED)
  rigger_add_test(rigger_security_test
    SOURCES security/security_test.cpp
    DEPS rigger_test_harness nlohmann_json::nlohmann_json LABEL integration TIMEOUT 180)
  add_dependencies(rigger_security_test task_controller scripted_executor riggerctl rigger-compose
    rigger-topic-catalog rigger_security_probe)
endif()
# The paper's crane scenario with every service secured: recipes/crane_insert.json through a
# permitted riggerctl while intruders try, on the real physics: alone, like the other scenario tests.
if(TARGET rigger_security_probe AND _scenario_ready)
  rigger_add_test(rigger_secure_scenario_test
    SOURCES security/secure_scenario_test.cpp
    DEPS rigger_test_harness rigger_cell_cad Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 480 RUN_SERIAL)
  add_dependencies(rigger_secure_scenario_test ${_scenario_services} riggerctl rigger-topic-catalog
    rigger_security_probe)
endif()
