# cmake -P script: install stereoguard into WORK_DIR/prefix, configure and build the example
# against it, simulate a 5-frame stereo folder and check that the example prints one event per
# frame, in order. Fails (FATAL_ERROR) on the first step that does not work.
set(frames 5)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name} failed (${rc}):\n${out}\n${err}")
  endif()
  set(step_out "${out}" PARENT_SCOPE)
  set(step_err "${err}" PARENT_SCOPE)
endfunction()

step("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(f include/sg/pipeline/runner.hpp lib/cmake/stereoguard/stereoguardConfig.cmake
          lib/cmake/stereoguard/stereoguardConfigVersion.cmake)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()

set(launcher "")
if(CXX_LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_LAUNCHER})
endif()
if(SANITIZE_FLAGS)
  list(APPEND launcher "-DCMAKE_CXX_FLAGS=${SANITIZE_FLAGS}"
       "-DCMAKE_EXE_LINKER_FLAGS=${SANITIZE_FLAGS}")
endif()
step("configure the example" ${CMAKE_COMMAND} -S ${EXAMPLE_DIR} -B ${WORK_DIR}/build
     -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix ${launcher})
step("build the example" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)

# A small approaching box, rendered into a stereo folder.
file(WRITE ${WORK_DIR}/small.yaml
  "name: small\nframes: ${frames}\n"
  "camera: {width: 321, height: 241, focal_px: 250, cx: 160, cy: 120}\n"
  "obstacles:\n"
  "  - {id: 1, size_m: [1.0, 1.5, 0.5], position_m: [0, 0.45, 4.0], velocity_mps: [0, 0, -3]}\n")
step("simulate" ${STEREOGUARD} simulate --scenario ${WORK_DIR}/small.yaml --out ${WORK_DIR}/folder)

step("run the example" ${WORK_DIR}/build/run_folder ${WORK_DIR}/folder)
string(REGEX MATCHALL "[^\n]+" lines "${step_out}")
list(LENGTH lines count)
if(NOT count EQUAL frames)
  message(FATAL_ERROR "expected ${frames} event lines, got ${count}:\n${step_out}")
endif()
set(i 0)
foreach(line IN LISTS lines)
  string(JSON frame ERROR_VARIABLE json_error GET "${line}" frame)
  if(json_error OR NOT frame EQUAL i)
    message(FATAL_ERROR "line ${i} is not the event of frame ${i}: ${line}")
  endif()
  math(EXPR i "${i} + 1")
endforeach()
if(NOT step_err MATCHES "frames processed  ${frames}")
  message(FATAL_ERROR "no summary on stderr:\n${step_err}")
endif()
message(STATUS "example printed ${count} events, one per frame:\n${step_out}")
