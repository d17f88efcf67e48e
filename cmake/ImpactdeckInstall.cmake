# Install rules and the CMake package (find_package(impactdeck)): libraries as namespaced targets
# impactdeck::<module>, their public headers, the `impactdeck` command with its Gmsh plugins beside
# it, impactdeckConfig.cmake + impactdeckConfigVersion.cmake. The libraries are static: their
# private dependencies (GSL, CGAL, assimp, MED, cairo, ...) are found again by the package config
# (cmake/impactdeckConfig.cmake.in). IMPACTDECK_CORE_ONLY installs common + collision only.
include_guard(GLOBAL)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(_impactdeck_modules common collision)
if(NOT IMPACTDECK_CORE_ONLY)
  list(APPEND _impactdeck_modules geometry contact sequence fem_export plot scene study)
endif()

set(_impactdeck_targets)
foreach(_m IN LISTS _impactdeck_modules)
  set_target_properties(impactdeck_${_m} PROPERTIES EXPORT_NAME ${_m})
  target_include_directories(impactdeck_${_m} PUBLIC $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  list(APPEND _impactdeck_targets impactdeck_${_m})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${_m}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.hpp")
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/generated/impactdeck/common/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/impactdeck/common)
if(NOT IMPACTDECK_CORE_ONLY)
  # Our interface targets for header-only / hand-found dependencies, linked PRIVATE to the static
  # libraries: exported too (as impactdeck::impactdeck_med, ...), with their absolute paths.
  list(APPEND _impactdeck_targets impactdeck_tomlplusplus impactdeck_med)
endif()
install(TARGETS ${_impactdeck_targets} EXPORT impactdeckTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT impactdeckTargets NAMESPACE impactdeck:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/impactdeck)
# CMake strips executables and shared objects only; a stripping install (IMPACTDECK_INSTALL_STRIP,
# `--strip`) also drops the static libraries' debug sections (their symbols stay: they link).
foreach(_t IN LISTS _impactdeck_targets)
  get_target_property(_type ${_t} TYPE)
  if(_type STREQUAL "STATIC_LIBRARY")
    install(CODE "if(CMAKE_INSTALL_DO_STRIP)
  execute_process(COMMAND \"${CMAKE_STRIP}\" --strip-debug
                  \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/$<TARGET_FILE_NAME:${_t}>\"
                  COMMAND_ERROR_IS_FATAL ANY)
endif()")
  endif()
endforeach()

if(NOT IMPACTDECK_CORE_ONLY)
  # The command and its plugins side by side: the plugin loader looks beside the executable.
  # Component `command` (with `python`: what `pip install .` takes, setup.py).
  install(TARGETS impactdeck RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT command)
  install(TARGETS impactdeck_gmsh_mesher impactdeck_gmsh_cad LIBRARY DESTINATION ${CMAKE_INSTALL_BINDIR}
          COMPONENT command)
  # Generated from the CLI definition at build time (cli/CMakeLists.txt).
  install(FILES ${PROJECT_BINARY_DIR}/cli/impactdeck.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT command)
  install(FILES ${PROJECT_BINARY_DIR}/cli/impactdeck.bash DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions
          RENAME impactdeck COMPONENT command)
endif()

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/impactdeckConfig.cmake.in
  ${PROJECT_BINARY_DIR}/impactdeckConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/impactdeck)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/impactdeckConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/impactdeckConfig.cmake ${PROJECT_BINARY_DIR}/impactdeckConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/impactdeck)
