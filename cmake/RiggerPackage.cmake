# The installed skill SDK: `cmake --install build --component sdk --prefix P`, then in another project
# `find_package(rigger)` (CMAKE_PREFIX_PATH=P) gives rigger::skill_sdk and the libraries it stands on
# (docs/skills.md).
include_guard(GLOBAL)
include(CMakePackageConfigHelpers)

# rigger_export(TARGET [HEADERS dir/...]): installs TARGET (a library made by rigger_add_library, or an
# interface library) into the export set as rigger::<name without rigger_>, with its public headers:
# the folder's include/ unless HEADERS names the folders whose contents go to <prefix>/include.
function(rigger_export target)
  cmake_parse_arguments(ARG "" "" "HEADERS" ${ARGN})
  string(REGEX REPLACE "^rigger_" "" short ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${short})
  install(TARGETS ${target} EXPORT rigger-targets ARCHIVE DESTINATION lib COMPONENT sdk)
  if(NOT ARG_HEADERS AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/include)
    set(ARG_HEADERS ${CMAKE_CURRENT_SOURCE_DIR}/include/)
  endif()
  foreach(dir IN LISTS ARG_HEADERS)
    install(DIRECTORY ${dir} DESTINATION include COMPONENT sdk FILES_MATCHING PATTERN "*.h" PATTERN "*.hpp")
  endforeach()
endfunction()

# The package files, once every exported library is defined (the top-level CMakeLists calls this last).
function(rigger_install_package)
  if(NOT TARGET rigger_skill_sdk)
    return()
  endif()
  set(dest lib/cmake/rigger)
  install(EXPORT rigger-targets NAMESPACE rigger:: FILE riggerTargets.cmake DESTINATION ${dest} COMPONENT sdk)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/riggerConfig.cmake.in
                                ${PROJECT_BINARY_DIR}/package/riggerConfig.cmake INSTALL_DESTINATION ${dest})
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/riggerConfigVersion.cmake
                                   VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/package/riggerConfig.cmake ${PROJECT_BINARY_DIR}/package/riggerConfigVersion.cmake
          DESTINATION ${dest} COMPONENT sdk)
endfunction()
