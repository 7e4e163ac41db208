# Markerless Localize on real processes: cell_sim (MuJoCo depth with noise) on the marker-free cell file,
# world_model, vision_tracker and the perception-skills executor; Localize with method model stores a pose
# within 5 mm and 1 degree of the truth or fails with a code, never a wrong pose.
if(TARGET cell_sim AND TARGET world_model AND TARGET vision_tracker AND TARGET skill_executor)
  rigger_add_test(rigger_markerless_localize_test
    SOURCES markerless_localize_test.cpp
    DEPS rigger_test_harness rigger_world_client Eigen3::Eigen nlohmann_json::nlohmann_json
    LABEL integration TIMEOUT 240 RUN_SERIAL)
  add_dependencies(rigger_markerless_localize_test cell_sim world_model vision_tracker skill_executor)
endif()
