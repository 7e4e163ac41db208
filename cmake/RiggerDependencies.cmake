# Every third-party dependency, found once. All come from Debian 12 packages (deploy/setup).
include_guard(GLOBAL)

find_package(CycloneDDS 0.10 REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.11 REQUIRED)
find_package(spdlog 1.10 REQUIRED)
find_package(CLI11 QUIET)
find_package(Threads REQUIRED)
find_package(SQLite3 REQUIRED)
find_package(yaml-cpp 0.7 REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(MODBUS REQUIRED IMPORTED_TARGET libmodbus>=3.1)
find_package(OpenCV 4.6 REQUIRED COMPONENTS core imgproc calib3d aruco)
find_package(mujoco 2.2 REQUIRED)
# Debian's mujoco 2.2.2 package lists /usr/include/libqhull_r/ as an include directory although
# libqhull-dev is not installed (MuJoCo's public headers do not need it), and CMake refuses imported
# targets with missing include paths: keep only the directories that exist.
get_target_property(rigger_mujoco_includes mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
set(rigger_mujoco_existing_includes "")
foreach(dir IN LISTS rigger_mujoco_includes)
  if(EXISTS "${dir}")
    list(APPEND rigger_mujoco_existing_includes "${dir}")
  endif()
endforeach()
set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${rigger_mujoco_existing_includes}")
# The simulated camera renders with MuJoCo headless: desktop OpenGL through EGL (libegl-dev, libgl-dev).
set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
if(RIGGER_BUILD_TESTS)
  find_package(GTest 1.12 REQUIRED)
  include(GoogleTest)
endif()
if(RIGGER_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# valijson and CLI11 are header-only; Debian ships no CMake config for valijson.
find_path(VALIJSON_INCLUDE_DIR valijson/validator.hpp REQUIRED)
if(NOT TARGET rigger_valijson)
  add_library(rigger_valijson INTERFACE)
  target_include_directories(rigger_valijson SYSTEM INTERFACE ${VALIJSON_INCLUDE_DIR})
endif()
if(NOT TARGET CLI11::CLI11)
  find_path(CLI11_INCLUDE_DIR CLI/CLI.hpp REQUIRED)
  add_library(CLI11::CLI11 INTERFACE IMPORTED)
  target_include_directories(CLI11::CLI11 INTERFACE ${CLI11_INCLUDE_DIR})
endif()

# OpenCascade 7.6 (Debian libocct-*-dev) for common/cad. Debian's OpenCASCADEConfig.cmake refers to the
# Draw libraries, which are not packaged: link the TK libraries by name instead.
find_path(OCCT_INCLUDE_DIR Standard.hxx PATH_SUFFIXES opencascade REQUIRED)
if(NOT TARGET rigger_occt)
  add_library(rigger_occt INTERFACE)
  target_include_directories(rigger_occt SYSTEM INTERFACE ${OCCT_INCLUDE_DIR})
  target_link_libraries(rigger_occt INTERFACE
    TKXDESTEP TKSTEP TKSTEPAttr TKSTEP209 TKSTEPBase TKXSBase TKRWMesh TKBinXCAF TKXCAF TKVCAF TKV3d
    TKService TKCAF TKLCAF TKCDF TKMesh TKShHealing TKBO TKPrim TKTopAlgo TKGeomAlgo TKBRep TKGeomBase
    TKG3d TKG2d TKMath TKernel)
endif()
find_package(OpenSSL REQUIRED COMPONENTS Crypto)
