# Registers the consumer test. Included from tests/CMakeLists.txt.
# The test installs this build into a prefix under the build tree and builds
# tests/consumer against it with find_package and with pkg-config (run.sh).
set(_wc_consumer_flags "")
if(WC_SANITIZE)
  # The installed shared library is built with ASan/UBSan; a program that
  # loads it must be linked with the same runtime (see run.sh).
  set(_wc_consumer_flags "-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all")
endif()
add_test(NAME consumer_install
  COMMAND bash "${CMAKE_CURRENT_LIST_DIR}/run.sh"
          "${PROJECT_BINARY_DIR}"
          "${CMAKE_CURRENT_BINARY_DIR}/consumer"
          "${CMAKE_C_COMPILER}"
          "${CMAKE_GENERATOR}"
          "${CMAKE_INSTALL_LIBDIR}"
          "${_wc_consumer_flags}")
set_tests_properties(consumer_install PROPERTIES
  SKIP_RETURN_CODE 77
  TIMEOUT 300
  LABELS "consumer;install")
unset(_wc_consumer_flags)
