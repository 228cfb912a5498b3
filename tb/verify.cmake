# `ranging verify` (tool/cmd_verify.cpp) end to end: it builds the Verilated receiver of a
# configuration at run time from tb/verify_driver.cpp, so it is a hardware test.
add_executable(test_verify_tool ${CMAKE_CURRENT_SOURCE_DIR}/test_verify_tool.cpp)
target_link_libraries(test_verify_tool PRIVATE nlohmann_json::nlohmann_json GTest::gtest GTest::gtest_main)
target_include_directories(test_verify_tool PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_definitions(test_verify_tool PRIVATE
  RANGING_SOURCE_DIR="${PROJECT_SOURCE_DIR}" RANGING_TOOL="$<TARGET_FILE:ranging>")
add_dependencies(test_verify_tool ranging)
gtest_discover_tests(test_verify_tool DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "hardware" TIMEOUT 900)
# The long run (ten distances with and without noise, long noise streams): label soak.
add_test(NAME verify_soak_default
  COMMAND ranging verify --config ${PROJECT_SOURCE_DIR}/configs/default.yaml --soak --quiet
          --out ${CMAKE_BINARY_DIR}/verify-soak)
set_tests_properties(verify_soak_default PROPERTIES LABELS "soak;hardware" TIMEOUT 3600)
