# One place for warnings and sanitizers, applied to every stereoguard target.
set(SG_SANITIZE_FLAGS "")
if(SG_ASAN)
  list(APPEND SG_SANITIZE_FLAGS -fsanitize=address -fno-omit-frame-pointer)
endif()
if(SG_UBSAN)
  list(APPEND SG_SANITIZE_FLAGS -fsanitize=undefined -fno-sanitize-recover=undefined)
endif()
if(SG_TSAN)
  list(APPEND SG_SANITIZE_FLAGS -fsanitize=thread)
endif()
if(SG_FUZZ)
  # Coverage for libFuzzer in every library; the fuzz targets add -fsanitize=fuzzer at link time.
  list(APPEND SG_SANITIZE_FLAGS -fsanitize=fuzzer-no-link,address,undefined
       -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
endif()

function(sg_target_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic ${SG_SANITIZE_FLAGS})
  target_link_options(${target} PRIVATE ${SG_SANITIZE_FLAGS})
endfunction()

# sg_library(<layer> SOURCES ... DEPS ...): static library sg_<layer> with alias sg::<layer>.
function(sg_library layer)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(sg_${layer} STATIC ${ARG_SOURCES})
  add_library(sg::${layer} ALIAS sg_${layer})
  target_include_directories(sg_${layer} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>)
  target_link_libraries(sg_${layer} PUBLIC ${ARG_DEPS})
  sg_target_options(sg_${layer})
  # Installed as sg::<layer> by cmake/sg_install.cmake (find_package(stereoguard)).
  set_target_properties(sg_${layer} PROPERTIES EXPORT_NAME ${layer})
  install(TARGETS sg_${layer} EXPORT stereoguardTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()

# sg_test(<name> SOURCES ... DEPS ... [LABELS ...]): a GoogleTest executable registered with CTest.
function(sg_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    SG_SHARED_DIR="${PROJECT_SOURCE_DIR}/../shared"
    SG_BINARY_DIR="${PROJECT_BINARY_DIR}")
  sg_target_options(${name})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  gtest_discover_tests(${name} PROPERTIES LABELS "${ARG_LABELS}" DISCOVERY_TIMEOUT 60)
endfunction()
