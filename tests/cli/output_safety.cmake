# Output that never destroys data, end to end.
#
#   TOOL      the stratmesh tool
#   INPUTS    the directory make-inputs filled
#   TINY      a 4-point PLY (its mesh about 300 bytes, its picture over 1 KB, its report
#             over 2 KB)
#   WORK_DIR  emptied and used as the working directory
#   SAMPLE    the bundled scan (30,000 points)
#   SANITIZED ON in a sanitizer build, whose shadow memory no address-space limit allows
#
# 1. Each pair of the input, -o, --report and --preview naming one file (the same path, a
#    symlink to it, or standard input redirected from it) is refused with exit 2 and a
#    message naming both options, and every file in the directory keeps its bytes; so are
#    two outputs on standard output (-, or - and /dev/stdout). The input may share a
#    character device with an output: /dev/null as both is read as an empty input.
# 2. A write that fails leaves the old output and no temporary: -o through a symlink to
#    /dev/full (a device, written directly and left a device), and a file size limit
#    (ulimit -f, which binds root too) on the mesh, on the report and on --stream's
#    output. The controls: the same runs without the failure write the files.
# 3. The outputs are published all or none: a report or a picture that fails (on /dev/full,
#    a device, written directly; or beyond a file size limit) leaves the mesh file as it
#    was, or absent, with and without --stream; a run refused midway writes nothing to
#    standard output, even with --stream's OBJ, whose lines come as the layers do.
# 4. Names as long as a file name may be (250 and 255 bytes) are written, and replaced, with
#    and without --stream: the temporaries beside them take a shorter name.
# 5. A reader that closes standard output early (| head -c 10): the tool says so and exits
#    with 3, not killed by SIGPIPE, and replaces no file, with and without --stream.
# 6. Under an address-space limit (ulimit -v) too small for --stream's default workspace,
#    the tool says to lower --stream-points, to a number that then works under that limit.
# 7. Whatever the address-space limit, from too little to load the tool to enough for the
#    run, on four threads: the tool ends with a message and an exit status, never aborted
#    (an exception it does not catch, a thread it cannot start), and leaves a whole report
#    and mesh or none, and no temporary.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
file(COPY "${INPUTS}/sorted.ply" DESTINATION "${WORK_DIR}")
file(CREATE_LINK sorted.ply "${WORK_DIR}/link.ply" SYMBOLIC)
file(WRITE "${WORK_DIR}/old.ply" "the old mesh")
file(WRITE "${WORK_DIR}/old.json" "the old report")
file(COPY "${TINY}" DESTINATION "${WORK_DIR}")
get_filename_component(tiny "${TINY}" NAME)
file(CREATE_LINK old.ply "${WORK_DIR}/old_link.ply" SYMBOLIC)

function(fail message)
  message(FATAL_ERROR "${message}")
endfunction()

# The directory's names and their contents' hashes, to compare before and after a run.
function(snapshot out)
  file(GLOB names RELATIVE "${WORK_DIR}" "${WORK_DIR}/*" "${WORK_DIR}/.*")
  list(SORT names)
  set(state "")
  foreach(name IN LISTS names)
    if(IS_SYMLINK "${WORK_DIR}/${name}")
      file(READ_SYMLINK "${WORK_DIR}/${name}" target)
      string(APPEND state "${name}->${target};")
    else()
      file(SHA256 "${WORK_DIR}/${name}" hash)
      string(APPEND state "${name}=${hash};")
    endif()
  endforeach()
  set(${out} "${state}" PARENT_SCOPE)
endfunction()

# run(EXIT regex args...): the tool in WORK_DIR must exit with EXIT and print `regex`; its
# standard output and error go to `last_stdout` and `last_stderr`, its standard input is
# `stdin_file` if set.
function(run expected_exit regex)
  set(streams OUTPUT_VARIABLE out)
  if(DEFINED stdin_file)
    list(APPEND streams INPUT_FILE "${stdin_file}")
  endif()
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK_DIR}"
    RESULT_VARIABLE code ERROR_VARIABLE err ${streams})
  set(last_stdout "${out}" PARENT_SCOPE)
  set(last_stderr "${err}" PARENT_SCOPE)
  message(STATUS "${ARGN}\n-- exit ${code}: ${err}")
  if(NOT "${code}" STREQUAL "${expected_exit}")
    fail("exit ${code}, expected ${expected_exit}: ${ARGN}\n${err}")
  endif()
  if(NOT err MATCHES "${regex}")
    fail("stderr does not match '${regex}': ${ARGN}\n${err}")
  endif()
endfunction()

# 1. Two names of one file.
set(clashes
  "sorted.ply -o sorted.ply|-o 'sorted.ply' is the same file as the input 'sorted.ply'"
  "sorted.ply -o link.ply|-o 'link.ply' is the same file as the input 'sorted.ply'"
  "link.ply -o sorted.ply|-o 'sorted.ply' is the same file as the input 'link.ply'"
  "sorted.ply -o m.ply --report sorted.ply|--report 'sorted.ply' is the same file as the input"
  "sorted.ply -o m.ply --report link.ply|--report 'link.ply' is the same file as the input"
  "sorted.ply -o m.ply --report m.ply|--report 'm.ply' is the same file as -o 'm.ply'"
  "sorted.ply -o old.ply --report old_link.ply|--report 'old_link.ply' is the same file as -o"
  "sorted.ply -o m.ply --report ./m.ply --stream --axis z --cuts 50|--report './m.ply' is the same file as -o"
  "sorted.ply -o m.ply --preview sorted.ply|--preview 'sorted.ply' is the same file as the input"
  "<sorted.ply - -o sorted.ply|-o 'sorted.ply' is the same file as the input \\(standard input\\)"
  "<sorted.ply - -o m.ply --report sorted.ply|--report 'sorted.ply' .* the input \\(standard input\\)"
  "<sorted.ply - -o m.ply --preview link.ply|--preview 'link.ply' .* the input \\(standard input\\)"
  "<sorted.ply - -o sorted.ply --stream --axis z --cuts 50|-o 'sorted.ply' .* \\(standard input\\)"
  "sorted.ply -o - --format ply --report /dev/stdout|--report '/dev/stdout' .* -o \\(standard output\\)")
foreach(clash IN LISTS clashes)
  string(REPLACE "|" ";" fields "${clash}")
  list(GET fields 0 args)
  list(GET fields 1 regex)
  unset(stdin_file)
  if(args MATCHES "^<([^ ]+) (.*)$")
    set(stdin_file "${WORK_DIR}/${CMAKE_MATCH_1}")
    set(args "${CMAKE_MATCH_2}")
  endif()
  separate_arguments(args UNIX_COMMAND "${args}")
  snapshot(before)
  run(2 "${regex}.*: give .* another path" "${TOOL}" ${args})
  snapshot(after)
  if(NOT before STREQUAL after)
    fail("the files changed:\n${before}\n${after}")
  endif()
endforeach()
unset(stdin_file)
# Two outputs on standard output; the control: one, and /dev/null both read and written.
foreach(args IN ITEMS "-o - --format obj --report -" "-o - --format obj --preview -"
    "-o m.ply --report - --preview -")
  separate_arguments(args UNIX_COMMAND "${args}")
  run(2 "at most one of -o, --report and --preview may be -" "${TOOL}" sorted.ply ${args})
endforeach()
run(0 "" "${TOOL}" sorted.ply -o - --format obj -q)
if(NOT last_stdout MATCHES "^# [^\n]*\nv ")
  fail("-o - wrote no OBJ to standard output")
endif()
set(stdin_file /dev/null)
run(3 "standard input: the file is empty" "${TOOL}" - -o /dev/null --format ply)
unset(stdin_file)

# 2. Failed writes.
snapshot(before)
if(EXISTS /dev/full)
  file(CREATE_LINK /dev/full "${WORK_DIR}/full.ply" SYMBOLIC)
  run(3 "full.ply: cannot write: No space left on device" "${TOOL}" sorted.ply -o full.ply -q)
  run(3 "full.ply: cannot write: No space left on device"
    "${TOOL}" sorted.ply -o full.ply -q --stream --axis z --cuts 50)
  file(REMOVE "${WORK_DIR}/full.ply")
  if(NOT IS_SYMLINK /dev/full AND NOT IS_DIRECTORY /dev/full)
    execute_process(COMMAND test -c /dev/full RESULT_VARIABLE not_a_device)
    if(not_a_device)
      fail("/dev/full is no longer a device")
    endif()
  endif()
endif()
# A limit of 64 blocks of 512 bytes: the sorted cylinder's mesh takes about 120 KB.
set(limited sh -c "ulimit -f 64 && exec \"$@\"" limited "${TOOL}")
run(3 "old.ply: cannot write: File too large" ${limited} sorted.ply -o old.ply -q)
run(3 "old.ply: cannot write: File too large" ${limited} sorted.ply -o old.ply -q --ascii)
run(3 "old.ply: cannot write: File too large"
  ${limited} sorted.ply -o old.ply -q --stream --axis z --cuts 50)
# The tiny mesh fits in 1 block, its report does not.
set(limited_1 sh -c "ulimit -f 1 && exec \"$@\"" limited "${TOOL}")
run(3 "old.json: cannot write: File too large" ${limited_1} ${tiny} -o tiny.ply -q --report old.json)
snapshot(after)
if(NOT before STREQUAL after)
  fail("a failed write changed the files or left a temporary:\n${before}\n${after}")
endif()
# The control: without the limit the same runs write the mesh and the report.
run(0 "" "${TOOL}" sorted.ply -o old.ply -q --report r.json)
file(SIZE "${WORK_DIR}/old.ply" mesh_bytes)
if(mesh_bytes LESS 1000 OR NOT EXISTS "${WORK_DIR}/r.json")
  fail("the control run did not replace old.ply (${mesh_bytes} bytes) or write r.json")
endif()
file(GLOB left "${WORK_DIR}/.*stratmesh*")
if(left)
  fail("temporaries left behind: ${left}")
endif()

# 3. All or none.
snapshot(before)
if(EXISTS /dev/full)
  run(3 "^stratmesh: /dev/full: cannot write: No space left on device\n$"
    "${TOOL}" sorted.ply -o old.ply --report /dev/full -q)
  run(3 "/dev/full: cannot write" "${TOOL}" sorted.ply -o new.ply --report /dev/full)
  run(3 "/dev/full: cannot write"
    "${TOOL}" sorted.ply -o new.ply --preview new.svg --report /dev/full -q)
  run(3 "/dev/full: cannot write" "${TOOL}" sorted.ply -o old.ply --preview /dev/full -q)
  run(3 "/dev/full: cannot write"
    "${TOOL}" sorted.ply -o old.ply --report /dev/full -q --stream --axis z --cuts 50)
endif()
run(3 "new.svg: cannot write: File too large"
  ${limited_1} ${tiny} -o new.ply --preview new.svg --report new.json -q)
run(1 "invalid_point"
  "${TOOL}" ${INPUTS}/sorted_nan.xyz -o - --format obj --stream --axis z --cuts 25,50,75)
if(NOT last_stdout STREQUAL "")
  fail("a refused run wrote to standard output")
endif()
snapshot(after)
if(NOT before STREQUAL after)
  fail("a failed output let another be written, or left a temporary:\n${before}\n${after}")
endif()

# 4. Long names.
string(REPEAT "n" 246 long)
string(REPEAT "s" 251 longest)
foreach(pass IN ITEMS create replace)
  run(0 "" "${TOOL}" sorted.ply -o ${long}.ply --report ${long}.json --preview ${long}.svg -q)
  run(0 "" "${TOOL}" sorted.ply -o ${longest}.ply -q --stream --axis z --cuts 50)
endforeach()
foreach(name IN ITEMS ${long}.ply ${long}.json ${long}.svg ${longest}.ply)
  file(SIZE "${WORK_DIR}/${name}" bytes)
  if(bytes LESS 1000)
    fail("${name} holds ${bytes} bytes")
  endif()
endforeach()
file(GLOB left "${WORK_DIR}/.*stratmesh*")
if(left)
  fail("temporaries left behind: ${left}")
endif()

# 5. Standard output closed early.
find_program(HEAD head)
if(HEAD)
  snapshot(before)
  foreach(args IN ITEMS "-o new.ply --report new.json --preview -"
      "-o - --format obj --report new.json"
      "-o - --format obj --report new.json --stream --axis z --cuts 50")
    separate_arguments(args UNIX_COMMAND "${args}")
    execute_process(COMMAND "${TOOL}" sorted.ply ${args} -q COMMAND "${HEAD}" -c 10
      WORKING_DIRECTORY "${WORK_DIR}" RESULTS_VARIABLE codes OUTPUT_VARIABLE out
      ERROR_VARIABLE err)
    message(STATUS "${args} | head -c 10\n-- exit ${codes}: ${err}")
    if(NOT codes STREQUAL "3;0" OR NOT err MATCHES
        "^stratmesh: standard output closed early \\(broken pipe\\): [^\n]*\n$")
      fail("| head -c 10: exit ${codes}, expected 3 and the message: ${args}\n${err}")
    endif()
    string(LENGTH "${out}" length)
    if(NOT length EQUAL 10)
      fail("head read ${length} bytes")
    endif()
  endforeach()
  snapshot(after)
  if(NOT before STREQUAL after)
    fail("a run cut short replaced a file or left a temporary:\n${before}\n${after}")
  endif()
endif()

# 6. The stream under a memory limit: 400 MB, where the default 3000000 points need about
#    540 MB (standard input, whose points are not counted beforehand).
if(NOT SANITIZED)
  set(stdin_file "${INPUTS}/sorted.xyz")
  set(capped sh -c "ulimit -v 400000 && exec \"$@\"" capped "${TOOL}")
  run(1 "cannot be allocated: lower --stream-points to [0-9]+ or fewer"
    ${capped} - -o streamed.ply --stream --axis z --cuts 50)
  string(REGEX MATCH "lower --stream-points to ([0-9]+)" advice "${last_stderr}")
  run(0 "" ${capped} - -o streamed.ply --stream --axis z --cuts 50 -q
    --stream-points ${CMAKE_MATCH_1})
  unset(stdin_file)
endif()

# 7. Memory limits.
if(NOT SANITIZED)
  foreach(limit RANGE 4000 30000 2000)
    execute_process(COMMAND sh -c "ulimit -v ${limit} && exec \"$@\"" limited "${TOOL}"
        "${SAMPLE}" -o new.ply --report new.json -q --threads 4
      WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_QUIET)
    message(STATUS "ulimit -v ${limit}: exit ${code}: ${err}")
    if(NOT code MATCHES "^(0|1|3|127)$" OR err MATCHES "terminate called")
      fail("ulimit -v ${limit}: exit ${code}\n${err}")
    endif()
    file(GLOB written "${WORK_DIR}/new.*" "${WORK_DIR}/.*stratmesh*")
    if(code EQUAL 0)
      list(LENGTH written count)
      if(NOT count EQUAL 2)
        fail("ulimit -v ${limit}: exit 0 but the files are ${written}")
      endif()
      file(REMOVE ${written})
    elseif(written)
      fail("ulimit -v ${limit}: exit ${code} but these are left: ${written}")
    endif()
  endforeach()
endif()
