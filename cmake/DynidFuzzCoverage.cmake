# Fuzzer coverage where the fuzzers go (issue 29, the sanitizer stage's share of CI).
#
# The asan preset compiles everything with -fsanitize=fuzzer-no-link so that one build serves the
# test suite and the fuzz/ harnesses. That flag instruments every comparison (trace-cmp) and every
# indirect call with a callback; in Eigen's inner loops this made the numeric code 2-3 times slower
# under the sanitizers than ASan+UBSan alone (docs/performance.md, "Build time"). The harnesses
# only feed the input layer (CSV, URDF, YAML, result JSON, project files, CLI parsing), so the
# numeric folders and the tests keep the edge counters (libFuzzer still sees where an input leads)
# and drop the comparison and indirect-call hooks.
set(DYNID_NUMERIC_FOLDERS dynamics regressor estimation excitation closed_loop identifiability
    signal sim physical load)
set(DYNID_LIGHT_COVERAGE -fno-sanitize-coverage=trace-cmp,indirect-calls)

if(DYNID_BUILD_FUZZERS)
  foreach(folder ${DYNID_NUMERIC_FOLDERS})
    file(GLOB numeric_sources ${PROJECT_SOURCE_DIR}/src/${folder}/*.cpp)
    set_property(SOURCE ${numeric_sources} APPEND PROPERTY COMPILE_OPTIONS ${DYNID_LIGHT_COVERAGE})
  endforeach()
endif()

# Light coverage for a target no harness links (the test executables).
function(dynid_light_coverage target)
  if(DYNID_BUILD_FUZZERS)
    target_compile_options(${target} PRIVATE ${DYNID_LIGHT_COVERAGE})
  endif()
endfunction()
