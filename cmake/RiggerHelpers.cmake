# Helpers so that every library, service and test target in rigger looks alike.
include_guard(GLOBAL)

set(RIGGER_WARNINGS -Wall -Wextra -Wpedantic -Wshadow)

# Compile options shared by every rigger C++ target.
function(rigger_target_defaults target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:${RIGGER_WARNINGS}>
    $<$<AND:$<COMPILE_LANGUAGE:CXX>,$<BOOL:${RIGGER_WERROR}>>:-Werror>)
  # The two trees, for tests, benchmarks and fuzzers only (a target with a source in a test/, bench/ or
  # fuzz/ folder, or below the top-level test/): a program finds its files through its data folder or its
  # configuration (rigger/base/install.hpp); InstallTest.NoProgramNamesTheSourceOrBuildTree fails when
  # code outside those folders names either. Keeping the clone's path off the other targets' command
  # lines also lets a compiler cache serve them to another clone of the same tree (deploy/setup).
  get_target_property(sources ${target} SOURCES)
  set(test_code FALSE)
  if(CMAKE_CURRENT_SOURCE_DIR MATCHES "^${PROJECT_SOURCE_DIR}/test(/|$)")
    set(test_code TRUE)
  endif()
  foreach(source IN LISTS sources)
    if(source MATCHES "(^|/)(test|bench|fuzz)/")
      set(test_code TRUE)
    endif()
  endforeach()
  if(test_code)
    target_compile_definitions(${target} PRIVATE
      RIGGER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      RIGGER_BINARY_DIR="${PROJECT_BINARY_DIR}")
  endif()
endfunction()

# Precompiled headers: the heavy third-party headers most translation units include (nlohmann/json,
# Eigen, spdlog, and GoogleTest in tests) are parsed once per build, not once per file. Two donor targets
# compile them, one position-independent (for the libraries) and one not (programs, tests); every rigger
# target reuses one of them. GCC falls back to the plain headers where a target's flags do not fit; clang
# refuses such a mismatch outright, so the fuzz tree (other flags per target) turns it off.
option(RIGGER_PCH "Precompile the heavy third-party headers once per build" ON)
set(RIGGER_PCH_HEADERS <algorithm> <chrono> <cmath> <functional> <map> <memory> <optional> <string> <vector>
    <Eigen/Geometry> <nlohmann/json.hpp> <spdlog/spdlog.h>)

# rigger_use_pch(TARGET pic|program|test): TARGET reuses the donor of its kind (made on first use).
function(rigger_use_pch target kind)
  if(NOT RIGGER_PCH)
    return()
  endif()
  set(donor rigger_pch_${kind})
  set(deps spdlog::spdlog nlohmann_json::nlohmann_json Eigen3::Eigen)
  if(kind STREQUAL "test")
    list(APPEND deps GTest::gtest GTest::gmock)
  endif()
  if(NOT TARGET ${donor})
    set(source ${PROJECT_BINARY_DIR}/pch/donor.cpp)
    if(NOT EXISTS ${source})
      file(WRITE ${source} "// The precompiled headers' donor (cmake/RiggerHelpers.cmake): no code of its own.\n")
    endif()
    add_library(${donor} STATIC EXCLUDE_FROM_ALL ${source})
    rigger_target_defaults(${donor})
    target_link_libraries(${donor} PRIVATE ${deps})
    set(headers ${RIGGER_PCH_HEADERS})
    if(kind STREQUAL "test")
      list(APPEND headers <gtest/gtest.h>)
    endif()
    if(kind STREQUAL "pic")
      set_target_properties(${donor} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    endif()
    target_precompile_headers(${donor} PRIVATE ${headers})
  endif()
  # The donor's definitions and include folders (not its libraries), so that the headers mean the same.
  foreach(dep IN LISTS deps)
    target_compile_definitions(${target} PRIVATE $<TARGET_PROPERTY:${dep},INTERFACE_COMPILE_DEFINITIONS>)
    target_include_directories(${target} SYSTEM PRIVATE $<TARGET_PROPERTY:${dep},INTERFACE_INCLUDE_DIRECTORIES>)
  endforeach()
  target_precompile_headers(${target} REUSE_FROM ${donor})
endfunction()

# Adds every immediate subfolder of DIR holding a CMakeLists.txt (honours RIGGER_ONLY).
function(rigger_add_subdirectories dir)
  file(GLOB children RELATIVE ${CMAKE_CURRENT_SOURCE_DIR}/${dir} ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/*/CMakeLists.txt)
  list(SORT children)
  foreach(child ${children})
    get_filename_component(name ${child} DIRECTORY)
    if(RIGGER_ONLY AND NOT name IN_LIST RIGGER_ONLY)
      # Also keep a folder when RIGGER_ONLY names one of its parts ("cell_sim/plc").
      set(wanted FALSE)
      foreach(item ${RIGGER_ONLY})
        if(item MATCHES "^${name}/")
          set(wanted TRUE)
        endif()
      endforeach()
      if(NOT wanted)
        continue()
      endif()
    endif()
    add_subdirectory(${dir}/${name})
  endforeach()
endfunction()

# Adds DIR when it has a CMakeLists.txt and RIGGER_ONLY does not exclude it.
function(rigger_add_optional_subdirectory dir)
  get_filename_component(name ${dir} NAME)
  if(RIGGER_ONLY AND NOT name IN_LIST RIGGER_ONLY AND NOT dir IN_LIST RIGGER_ONLY)
    return()
  endif()
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/CMakeLists.txt)
    add_subdirectory(${dir})
  endif()
endfunction()

# rigger_add_library(NAME SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# A static library, also known as rigger::<NAME without rigger_>; headers under <folder>/include are public. A library with an include/ folder keeps
# src/ private (its own tests get it from rigger_add_test): other code reaches it only through include/.
# A service's or tool's core without include/ exposes src/ to what links it, i.e. its main and its tests.
function(rigger_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  # rigger_dds is also rigger::dds: a misspelt rigger:: name fails at configure time instead of being
  # taken for a linker flag.
  string(REGEX REPLACE "^rigger_" "" short ${name})
  add_library(rigger::${short} ALIAS ${name})
  rigger_target_defaults(${name})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  rigger_use_pch(${name} pic)
  set(src_scope PUBLIC)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/include)
    # Installed libraries (rigger_export) find their headers in <prefix>/include.
    target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                              $<INSTALL_INTERFACE:include>)
    set(src_scope PRIVATE)
  endif()
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src)
    target_include_directories(${name} ${src_scope} $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/src>)
  endif()
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

# Where installed data goes (<prefix>/share/rigger), the same folder the build tree stages it in:
# rigger/base/install.hpp's data_dir().
set(RIGGER_DATA_DESTINATION share/rigger)

# A benchmark program: in <build>/bench, built by the target rigger_benches (test/bench/run), not by `all`.
function(rigger_bench_target name)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bench EXCLUDE_FROM_ALL TRUE)
  add_dependencies(rigger_benches ${name})
endfunction()

# rigger_add_executable(NAME SOURCES ... [DEPS ...] [BENCH | NOT_INSTALLED]): a program placed in
# <build>/bin and installed into <prefix>/bin (`cmake --install`), like every service and user tool.
# BENCH: a benchmark, placed in <build>/bench, built only by rigger_benches, not installed. NOT_INSTALLED: a test helper in bin/.
function(rigger_add_executable name)
  cmake_parse_arguments(ARG "BENCH;NOT_INSTALLED" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  rigger_target_defaults(${name})
  rigger_use_pch(${name} program)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src)  # a service's main and its folder's benches see its private headers
    target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  if(ARG_BENCH)
    rigger_bench_target(${name})
    return()
  endif()
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
  if(NOT ARG_NOT_INSTALLED)
    install(TARGETS ${name} RUNTIME DESTINATION bin)
  endif()
endfunction()

# rigger_add_service(NAME CORE_SOURCES ... [DEPS ...]):
#   rigger_<NAME>_core (static library: everything but main) and the executable <NAME> (src/main.cpp).
function(rigger_add_service name)
  cmake_parse_arguments(ARG "" "" "CORE_SOURCES;DEPS" ${ARGN})
  rigger_add_library(rigger_${name}_core SOURCES ${ARG_CORE_SOURCES} PUBLIC_DEPS ${ARG_DEPS})
  rigger_add_executable(${name} SOURCES src/main.cpp DEPS rigger_${name}_core)
endfunction()

# rigger_add_test(NAME SOURCES ... DEPS ... LABEL unit|dds|integration|timing|lab [TIMEOUT s] [RUN_SERIAL]
#                 [TIMING gtest-filter] [LAB gtest-filter]) (lab: on demand, not test/run)
# One GoogleTest binary; each test case becomes a ctest test with the label and a timeout.
# RUN_SERIAL: for tests that assert a deadline (e.g. discovery within 3 s) and must not share the
# machine's two cores with the rest of the suite.
# TIMING: the test cases matching the filter (e.g. "Suite.A:Suite.B") are labelled `timing` instead: they
# assert a real-time target, and test/run runs them one at a time after the rest, with the shipped
# liveliness lease (label timing alone does the same for a whole binary).
# LAB: the test cases matching the filter are labelled `lab` instead: a measurement run on demand
# (ctest -L lab), not by test/run.
function(rigger_add_test name)
  if(NOT RIGGER_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "RUN_SERIAL" "LABEL;TIMEOUT;TIMING;LAB" "SOURCES;DEPS" ${ARGN})
  if(NOT ARG_LABEL)
    message(FATAL_ERROR "rigger_add_test(${name}): LABEL is required (unit, dds, integration, timing, lab)")
  endif()
  if(NOT ARG_TIMEOUT)
    if(ARG_LABEL STREQUAL "unit")
      set(ARG_TIMEOUT 60)
    else()
      set(ARG_TIMEOUT 120)
    endif()
  endif()
  add_executable(${name} ${ARG_SOURCES})
  rigger_target_defaults(${name})
  rigger_use_pch(${name} test)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src)  # a library's tests see its private headers
    target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gmock GTest::gtest_main)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  set(serial FALSE)
  if(ARG_RUN_SERIAL)
    set(serial TRUE)
  endif()
  set(environment "RIGGER_BIN_DIR=${PROJECT_BINARY_DIR}/bin;RIGGER_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  if(ARG_TIMING AND ARG_LAB)
    message(FATAL_ERROR "rigger_add_test(${name}): TIMING and LAB together are not supported")
  endif()
  # The cases a TIMING or LAB filter names are discovered apart, with their own label (timing cases alone).
  set(split_filter "")
  if(ARG_TIMING)
    set(split_filter "${ARG_TIMING}")
    set(split_label timing)
    set(split_serial TRUE)
  elseif(ARG_LAB)
    set(split_filter "${ARG_LAB}")
    set(split_label lab)
    set(split_serial ${serial})
  endif()
  if(split_filter)
    gtest_discover_tests(${name} TEST_FILTER "-${split_filter}"
      DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS ${ARG_LABEL} TIMEOUT ${ARG_TIMEOUT} RUN_SERIAL ${serial} ENVIRONMENT "${environment}")
    gtest_discover_tests(${name} TEST_FILTER "${split_filter}"
      DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS ${split_label} TIMEOUT ${ARG_TIMEOUT} RUN_SERIAL ${split_serial} ENVIRONMENT "${environment}")
    return()
  endif()
  gtest_discover_tests(${name}
    DISCOVERY_TIMEOUT 60
    PROPERTIES LABELS ${ARG_LABEL} TIMEOUT ${ARG_TIMEOUT} RUN_SERIAL ${serial} ENVIRONMENT "${environment}")
endfunction()

# rigger_add_fuzzer(NAME SOURCES ... DEPS ... [CORPUS dir] [SECONDS n]): a libFuzzer target (clang
# only), registered as a ctest test (label fuzz) that runs it for SECONDS (default 10) starting from the
# seed corpus CORPUS (read-only; new inputs go to a scratch folder in the build tree). test/run builds
# the fuzz tree with -fsanitize=fuzzer-no-link everywhere, so library code gives coverage feedback too.
function(rigger_add_fuzzer name)
  if(NOT RIGGER_BUILD_FUZZ)
    return()
  endif()
  cmake_parse_arguments(ARG "" "SECONDS;CORPUS" "SOURCES;DEPS" ${ARGN})
  if(NOT ARG_SECONDS)
    set(ARG_SECONDS 10)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  rigger_target_defaults(${name})
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src)
    target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  endif()
  target_compile_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/fuzz)
  add_dependencies(rigger_fuzzers ${name})
  set(corpus_args "")
  if(ARG_CORPUS)
    set(scratch ${PROJECT_BINARY_DIR}/fuzz-corpus/${name})
    file(MAKE_DIRECTORY ${scratch})
    get_filename_component(seed ${ARG_CORPUS} ABSOLUTE)
    set(corpus_args ${scratch} ${seed})
  endif()
  add_test(NAME ${name} COMMAND ${name} -max_total_time=${ARG_SECONDS} -rss_limit_mb=2048 ${corpus_args})
  set_tests_properties(${name} PROPERTIES LABELS fuzz TIMEOUT ${ARG_SECONDS}0)
endfunction()

# rigger_targets_exist(VAR target...): VAR is TRUE when every target is configured (RIGGER_ONLY may leave
# some out), for tests that start several services.
function(rigger_targets_exist var)
  foreach(t IN LISTS ARGN)
    if(NOT TARGET ${t})
      set(${var} FALSE PARENT_SCOPE)
      return()
    endif()
  endforeach()
  set(${var} TRUE PARENT_SCOPE)
endfunction()
