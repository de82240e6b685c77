# cmake -DREPORT=research_apart.txt -DSOURCE_DIR=<project> -P research_apart_check.cmake
# (tests/research_apart.cmake): no product library links research, no product source includes
# a research header, and `sim` reaches research through goal_move.hpp only.
file(STRINGS ${REPORT} lines)
set(failed FALSE)
set(libs 0)
foreach(line ${lines})
  if(line MATCHES "^LINKS ")
    message("product library ${line}")
    set(failed TRUE)
  else()
    math(EXPR libs "${libs} + 1")
  endif()
endforeach()
file(GLOB_RECURSE sources LIST_DIRECTORIES false
     ${SOURCE_DIR}/config/*.[ch]pp ${SOURCE_DIR}/dynamics/*.[ch]pp ${SOURCE_DIR}/input/*.[ch]pp
     ${SOURCE_DIR}/scaling/*.[ch]pp ${SOURCE_DIR}/sim_backend/*.[ch]pp
     ${SOURCE_DIR}/valves/*.[ch]pp ${SOURCE_DIR}/app/*.[ch]pp)
set(files 0)
foreach(f ${sources})
  if(f MATCHES "/app/cli/research/")
    continue()
  endif()
  math(EXPR files "${files} + 1")
  file(STRINGS ${f} hits REGEX "#include \"(craneassist/(mhsb|paths|planner|studies)/|research/)")
  foreach(h ${hits})
    if(f MATCHES "/app/cli/(main|sim_command)\\.cpp$" AND
       (h MATCHES "research/goal_move\\.hpp" OR (f MATCHES "main\\.cpp$" AND h MATCHES "research/[a-z_]+_command\\.hpp")))
      continue()  # the executable registers the research group; sim's goal move
    endif()
    message("${f}: ${h}")
    set(failed TRUE)
  endforeach()
endforeach()
if(failed)
  message(FATAL_ERROR "research is not apart from the product (above)")
endif()
message("research apart OK: ${libs} product libraries link no research library, ${files} product sources include no research header")
