# What `cmake --install` puts where, and the CMake package a C++ program finds with
# find_package(eamos). Included from the top-level CMakeLists.txt after every component, so the
# components' own CMakeLists stay about building; this file is the one list of what is public.
#
# Layout under the prefix (GNUInstallDirs):
#   bin/eamos                                  the command
#   libexec/eamos/eamos-fly                    its commands that fly or serve (run, launch, dex, ...)
#   libexec/eamos/eamos-credentials            a compile's last step: the DDS Security credentials
#   include/eamos/<component>/*.h              public headers, included as "dex/runner.h"
#   lib/libeamos_*.a, lib/cmake/eamos/         the libraries and the package (eamos::dex, ...)
#   lib/systemd/system/eamos-dex@.service      the DEX as a service (docs/deploy.md)
#   share/man/man1/eamos*.1                    man pages made from --help (packaging/man_pages.cmake)
#   share/bash-completion/completions/eamos, share/zsh/.../_eamos
#   share/eamos/examples/, share/doc/eamos/
# Two install components: `runtime` (the command and what a drone or a ground station needs)
# and `dev` (headers, libraries, CMake package); cpack makes one .deb of each (packaging/cpack.cmake).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(EAMOS_INCLUDE_DIR ${CMAKE_INSTALL_INCLUDEDIR}/eamos)
set(EAMOS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/eamos)

# eamos_export(TARGET NAME DIR HEADERS...): TARGET becomes eamos::NAME for a program that
# links it, here (an alias) and installed; HEADERS (in src/DIR, each one of its public headers,
# cmake/layers.cmake) are the ones its users may include: everything an installed header
# includes must be installed too (InstallTree.* checks). The build's include roots stay in
# the build (BUILD_INTERFACE); an installed target's users find include/eamos.
function(eamos_export target name dir)
  set(headers ${ARGN})
  get_target_property(public ${target} EAMOS_PUBLIC_HEADERS)
  foreach(h IN LISTS headers)
    if(NOT h IN_LIST public)
      message(FATAL_ERROR "eamos_export(${target}): src/${dir}/${h} is not one of its public headers")
    endif()
  endforeach()
  list(TRANSFORM headers PREPEND ${PROJECT_SOURCE_DIR}/src/${dir}/)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_compile_features(${target} INTERFACE cxx_std_20)
  install(FILES ${headers} DESTINATION ${EAMOS_INCLUDE_DIR}/${dir} COMPONENT dev)
  add_library(eamos::${name} ALIAS ${target})
  set_property(GLOBAL APPEND PROPERTY EAMOS_EXPORTED_TARGETS ${target})
endfunction()

eamos_export(eamos_vocab vocab vocab kinds.h)
eamos_export(eamos_diag diag diag source.h diagnostics.h)
eamos_export(eamos_fleet fleet fleet catalog.h fleet.h link_url.h)
eamos_export(eamos_lang lang lang ast.h token.h lexer.h parser.h checker.h)
eamos_export(eamos_graph graph graph amt.h meg.h mdg.h pipeline.h export.h)
eamos_export(eamos_deploy deploy deploy mission_file.h synthesize.h drone_package.h)
eamos_export(eamos_mid mid mid drone_api.h sensor_values.h event_loop.h adapter_registry.h adapter_drone.h action_tracker.h
             requests.h mover.h state_broker.h location_validator.h timeouts.h vec.h)
eamos_export(eamos_dex dex dex bridge.h engine.h expr.h failsafe.h failure.h latency.h mission.h observer.h runner.h trace.h
             trace_writers.h)
eamos_export(eamos_trace trace trace plot.h trace_schema.h)
eamos_export(eamos_sim sim sim battery.h motion.h sim_adapter.h sim_drone.h)
eamos_export(eamos_mavlink mavlink mavlink crc.h enums.h field_def.h fields.h frame.h link.h messages.h payloads.h
             signing.h)
eamos_export(eamos_mavlink_adapter mavlink_adapter mavlink_adapter adapter.h autopilot.h autopilot_params.h
             autopilot_texts.h camera.h command_sender.h link_watch.h mavlink_drone.h mavlink_options.h
             fence_upload.h mode_commands.h orbit_flight.h setpoint_pacer.h setpoint_stream.h telemetry.h vehicle_clock.h
             vehicle_link.h)
# version.h (EAMOS_VERSION) is generated into the build tree.
set_target_properties(eamos_version PROPERTIES EXPORT_NAME version
                      INTERFACE_INCLUDE_DIRECTORIES "$<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>")
install(FILES ${PROJECT_BINARY_DIR}/generated/version.h DESTINATION ${EAMOS_INCLUDE_DIR} COMPONENT dev)
add_library(eamos::version ALIAS eamos_version)
get_property(exported GLOBAL PROPERTY EAMOS_EXPORTED_TARGETS)

install(TARGETS eamos RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
# The commands that fly or serve, and a compile's credentials, which `eamos` hands over to
# (src/cli/CMakeLists.txt, src/security/CMakeLists.txt).
install(TARGETS eamos-fly eamos-credentials RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/eamos COMPONENT runtime)
install(TARGETS ${exported} eamos_version EXPORT eamosTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${EAMOS_INCLUDE_DIR})
install(EXPORT eamosTargets NAMESPACE eamos:: DESTINATION ${EAMOS_CMAKE_DIR} COMPONENT dev)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/eamosConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/packaging/eamosConfig.cmake
                              INSTALL_DESTINATION ${EAMOS_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/packaging/eamosConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/packaging/eamosConfig.cmake ${PROJECT_BINARY_DIR}/packaging/eamosConfigVersion.cmake
        DESTINATION ${EAMOS_CMAKE_DIR} COMPONENT dev)

# The DEX as a systemd service; the same text `eamos compile --package` writes (src/deploy).
install(FILES ${PROJECT_SOURCE_DIR}/config/eamos-dex@.service
        DESTINATION lib/systemd/system COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/config/cyclonedds-network.xml ${PROJECT_SOURCE_DIR}/config/cyclonedds-loopback.xml
              ${PROJECT_SOURCE_DIR}/config/cyclonedds-hosts.xml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/eamos/config COMPONENT runtime)

# Completions: bash-completion loads completions/eamos on demand; zsh finds _eamos on its
# fpath, which on Debian has vendor-completions under /usr and site-functions under
# /usr/local. Decided when installing: cpack installs under a staging folder ending in /usr.
install(FILES ${CMAKE_CURRENT_LIST_DIR}/eamos.bash RENAME eamos
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions COMPONENT runtime)
install(CODE "
  if(CMAKE_INSTALL_PREFIX MATCHES \"/usr$\")
    set(eamos_zsh_dir vendor-completions)
  else()
    set(eamos_zsh_dir site-functions)
  endif()
  file(INSTALL DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/zsh/\${eamos_zsh_dir}\" TYPE FILE
       FILES \"${CMAKE_CURRENT_LIST_DIR}/_eamos\")" COMPONENT runtime)

# Man pages: help2man over `eamos --help` and every `eamos SUBCOMMAND --help`, at build time.
find_program(EAMOS_HELP2MAN help2man)
if(NOT EAMOS_HELP2MAN)
  message(FATAL_ERROR "help2man not found: install help2man (scripts/install-deps.sh does)")
endif()
set(man_dir ${PROJECT_BINARY_DIR}/man)
add_custom_command(OUTPUT ${man_dir}/eamos.1
  COMMAND ${CMAKE_COMMAND} -DEAMOS=$<TARGET_FILE:eamos> -DHELP2MAN=${EAMOS_HELP2MAN} -DOUT=${man_dir}
          -DVERSION=${PROJECT_VERSION} -DINCLUDE=${CMAKE_CURRENT_LIST_DIR}/eamos.h2m
          -P ${CMAKE_CURRENT_LIST_DIR}/man_pages.cmake
  DEPENDS eamos ${CMAKE_CURRENT_LIST_DIR}/man_pages.cmake ${CMAKE_CURRENT_LIST_DIR}/eamos.h2m
  COMMENT "Writing the man pages from eamos --help"
  VERBATIM)
add_custom_target(eamos_man ALL DEPENDS ${man_dir}/eamos.1)
install(DIRECTORY ${man_dir}/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime
        FILES_MATCHING PATTERN "*.1")

install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DATADIR}/eamos/examples
        COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs COMPONENT runtime)
