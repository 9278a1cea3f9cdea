# Writes the man pages from the command's own help, so they say what `--help` says:
# eamos.1 from `eamos --help` (with eamos.h2m's sections) and eamos-SUB.1 from each
# `eamos SUB --help`, named by the "Subcommands:" list of `eamos --help`. Run at build time:
#   cmake -DEAMOS=path/to/eamos -DHELP2MAN=help2man -DOUT=dir -DVERSION=x.y.z -DINCLUDE=eamos.h2m -P man_pages.cmake
foreach(v EAMOS HELP2MAN OUT VERSION INCLUDE)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "man_pages.cmake: -D${v}=... is required")
  endif()
endforeach()

execute_process(COMMAND ${EAMOS} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "man_pages.cmake: `${EAMOS} --help` failed (${rc})")
endif()
# Each subcommand is a line "  NAME   DESCRIPTION" after "Subcommands:". A ';' would split
# the line in a CMake list: it is held as a placeholder until written.
string(REGEX REPLACE "^.*\nSubcommands:\n" "" listing "${help}")
string(REPLACE ";" "<semicolon>" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(subcommands "")
foreach(line IN LISTS lines)
  if(line MATCHES "^  ([a-z][a-z0-9-]*)  +(.*)$")
    list(APPEND subcommands ${CMAKE_MATCH_1})
    set(description_${CMAKE_MATCH_1} "${CMAKE_MATCH_2}")
  endif()
endforeach()
if(NOT subcommands)
  message(FATAL_ERROR "man_pages.cmake: no subcommands in `eamos --help`")
endif()

file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT}/bin)
set(see_also "")
foreach(sub IN LISTS subcommands)
  string(APPEND see_also ".BR eamos-${sub} (1),\n")
endforeach()
string(REGEX REPLACE ",\n$" "\n" see_also "${see_also}")

# The NAME line comes from an include file: a description holds characters (';') that a
# command line built by CMake would not keep.
function(help2man program output)
  # The help is UTF-8 (an em dash); help2man reads it in the C locale unless told.
  execute_process(COMMAND ${HELP2MAN} --locale=C.UTF-8 --no-info --no-discard-stderr --version-string=${VERSION}
                          ${ARGN} --output=${output} ${program}
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "man_pages.cmake: help2man failed on ${program}: ${err}")
  endif()
endfunction()

foreach(sub IN LISTS subcommands)
  # help2man runs a program with --help: this one is `eamos SUB`.
  set(wrapper ${OUT}/bin/eamos-${sub})
  file(WRITE ${wrapper} "#!/bin/sh\nexec '${EAMOS}' ${sub} \"$@\"\n")
  file(CHMOD ${wrapper} PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE)
  string(REPLACE "<semicolon>" ";" description "${description_${sub}}")
  file(WRITE ${OUT}/eamos-${sub}.h2m "[NAME]\neamos-${sub} \\- ${description}\n[SEE ALSO]\n.BR eamos (1)\n")
  help2man(${wrapper} ${OUT}/eamos-${sub}.1 --include=${OUT}/eamos-${sub}.h2m)
endforeach()

file(WRITE ${OUT}/eamos.h2m
     "[NAME]\neamos \\- write a multidrone mission as a short program; every drone runs its part\n"
     "[SEE ALSO]\n${see_also}")
help2man(${EAMOS} ${OUT}/eamos.1 --include=${INCLUDE} --include=${OUT}/eamos.h2m)
