# Which headers a component shows the others. Each library under src/ has two include roots
# in the build tree, both made of symbolic links into src/ (so an edited header needs no
# reconfigure, and a compiler message names the real file's contents):
#   build/include/<dir>/<dir>/x.h      its public headers: the library's PUBLIC include root,
#                                      seen by every target that links it
#   build/private/<dir>/<dir> -> src/<dir>   all of its headers: a PRIVATE root, its own sources only
# src/ itself is nobody's include directory, so a library that includes a header of a
# component it does not link, or a private header of one it does, fails to compile. The
# allowed links are docs/architecture.md's table (tests/architecture checks both ways).
# Tests, benchmarks and fuzzers look inside components: their folders add src/ themselves.

# eamos_layer(TARGET DIR [PRIVATE_HEADERS h...]): TARGET is the library built from src/DIR.
# Every header of src/DIR is public but those named. An INTERFACE library gets only the public
# root; a module or executable (nobody links it) only the private one.
function(eamos_layer target dir)
  cmake_parse_arguments(L "" "" "PRIVATE_HEADERS" ${ARGN})
  set(source ${PROJECT_SOURCE_DIR}/src/${dir})
  set(public_root ${PROJECT_BINARY_DIR}/include/${dir})
  set(private_root ${PROJECT_BINARY_DIR}/private/${dir})
  foreach(h IN LISTS L_PRIVATE_HEADERS)
    if(NOT EXISTS ${source}/${h})
      message(FATAL_ERROR "eamos_layer(${target}): src/${dir}/${h} does not exist; list only headers of src/${dir}")
    endif()
  endforeach()
  # CONFIGURE_DEPENDS: a header added or removed re-runs CMake at the next build.
  file(GLOB headers CONFIGURE_DEPENDS RELATIVE ${source} ${source}/*.h)
  if(L_PRIVATE_HEADERS)
    list(REMOVE_ITEM headers ${L_PRIVATE_HEADERS})
  endif()
  get_target_property(type ${target} TYPE)
  if(NOT type MATCHES "^(MODULE_LIBRARY|EXECUTABLE)$")
    # Made afresh, so a header removed or made private leaves no link behind.
    file(REMOVE_RECURSE ${public_root})
    file(MAKE_DIRECTORY ${public_root}/${dir})
    foreach(h IN LISTS headers)
      file(CREATE_LINK ${source}/${h} ${public_root}/${dir}/${h} SYMBOLIC)
    endforeach()
    set_property(TARGET ${target} PROPERTY EAMOS_PUBLIC_HEADERS ${headers})
  endif()
  if(type STREQUAL "INTERFACE_LIBRARY")
    target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${public_root}>)
    return()
  endif()
  if(NOT EXISTS ${private_root}/${dir})
    file(MAKE_DIRECTORY ${private_root})
    file(CREATE_LINK ${source} ${private_root}/${dir} SYMBOLIC)
  endif()
  # The private root first: within the library every one of its headers is found there, by
  # one path, whichever file includes it.
  target_include_directories(${target} PRIVATE ${private_root})
  if(NOT type MATCHES "^(MODULE_LIBRARY|EXECUTABLE)$")
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${public_root}>)
  endif()
endfunction()
