# The installed tree works on its own: `cmake --install` into a scratch prefix, then
# - tools/examples, built as an outside project with find_package(Metriplex) and run (it
#   builds a scene with the builder API, runs 100 EEM steps and IDA, and exits 1 unless EEM's
#   energy balance holds to round-off),
# - the installed program on an installed example scene,
# - the installed Python package.
# Run by ctest as: cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DPYTHON=... -P check_install.cmake
function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE output)
  message("${output}")
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${what} failed (${status})")
  endif()
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
run_step("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
run_step("configuring the consumer" ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tools/examples -B ${WORK_DIR}/consumer
         -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
run_step("building the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/consumer)
run_step("the consumer" ${WORK_DIR}/consumer/thermo_springs_in_code)
run_step("the installed program" ${prefix}/bin/metriplex run ${prefix}/share/metriplex/scenes/two_thermo_springs.xml
         --t-end 2 --out ${WORK_DIR}/run)
run_step("the installed Python package" ${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/lib/python3/dist-packages
         ${PYTHON} -c "import metriplex; r = metriplex.run('${SOURCE_DIR}/scenes/two_thermo_springs.xml', t_end=2); assert r.ok")
