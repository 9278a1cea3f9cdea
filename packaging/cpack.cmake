# `cpack -G DEB` in the build folder: two Debian packages from the two install components.
#   eamos      the command, man pages, completions, examples, docs and the DEX's systemd unit;
#              Depends from dpkg-shlibdeps over the installed binary (the shared libraries it
#              really loads), so they are the Debian packages it runs with.
#   eamos-dev  headers, static libraries and the CMake package; Depends on eamos and on the
#              -dev packages find_package(eamos) needs (packaging/eamosConfig.cmake.in).
set(CPACK_PACKAGE_NAME eamos)
set(CPACK_PACKAGE_VENDOR "eamos")
# The Maintainer field; whoever builds packages for others sets their own name and address.
set(EAMOS_PACKAGE_MAINTAINER "eamos maintainers" CACHE STRING "Maintainer of the .deb packages (Name <address>)")
set(CPACK_PACKAGE_CONTACT "${EAMOS_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Multidrone missions as one short program, run on every drone")
set(CPACK_PACKAGE_DESCRIPTION "eamos compiles a mission for a fleet of heterogeneous drones, written as one
 short program, into one mission file per drone; flies it in the built-in simulator or on
 PX4 and ArduPilot vehicles over MAVLink; and runs each drone's part on its own computer,
 synchronised with the others over Cyclone DDS with DDS Security.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_STRIP_FILES ON)  # the command only: static archives are never stripped
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_COMPRESSION_TYPE gzip)  # xz takes four times as long on the 20 MB command

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME eamos)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
# `eamos graph --format svg`, `--plot`'s graphs and the monitor's run Graphviz's `dot`.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "graphviz")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "chrony")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA ${CMAKE_CURRENT_LIST_DIR}/postinst)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_STRICT_PERMISSION ON)

set(CPACK_DEBIAN_DEV_PACKAGE_NAME eamos-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "eamos (= ${PROJECT_VERSION}), nlohmann-json3-dev, libyaml-cpp-dev, nettle-dev, libssl-dev, pkg-config")

include(CPack)
