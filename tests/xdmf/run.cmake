# Run shear.nml with a bare relative output name, then open the XDMF file with the readers:
# by absolute path from another folder, by bare name from its folder (the XDMF 2 reader; the
# Xdmf3 library resolves a bare name against itself, 'x.xmfx.h5', so it gets './x.xmf').
# -DEXE= -DPYTHON= -DCASE= -DCHECK= -DWORK_DIR= [-DLAUNCH="mpirun;-n;3;..."]: with LAUNCH the
# run is made by several processes (the file they write together in an MPI build).
set(run_dir ${WORK_DIR}/run)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${run_dir})
execute_process(COMMAND ${LAUNCH} ${EXE} run ${CASE} -o shear.h5 WORKING_DIRECTORY ${run_dir}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "empm run: status ${rc}\n${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "empm run failed")
endif()
foreach(f shear.h5 shear.xmf)
  if(NOT EXISTS ${run_dir}/${f})
    message(FATAL_ERROR "${f} is missing")
  endif()
endforeach()
foreach(f shear.h5.partial shear.xmf.partial)
  if(EXISTS ${run_dir}/${f})
    message(FATAL_ERROR "${f} was left behind")
  endif()
endforeach()
# 4 x 4 cells of 2 x 2 particles; frames at t = 0 (default), 5e-4 (snapshot_times), 1e-3 (final).
set(expect 64 0 5e-4 1e-3)
foreach(mode "xdmf2,xdmf3;${run_dir}/shear.xmf;${WORK_DIR}" "xdmf2;shear.xmf;${run_dir}"
             "xdmf3;./shear.xmf;${run_dir}")
  list(GET mode 0 readers)
  list(GET mode 1 file)
  list(GET mode 2 cwd)
  execute_process(COMMAND ${PYTHON} ${CHECK} ${readers} ${file} ${expect}
                  WORKING_DIRECTORY ${cwd} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${readers} ${file} (in ${cwd}): status ${rc}\n${out}${err}")
  if(rc EQUAL 77)
    message(FATAL_ERROR "VTK's XDMF readers are missing: run scripts/setup-deps")
  elseif(NOT rc EQUAL 0)
    message(FATAL_ERROR "the XDMF check failed")
  endif()
endforeach()
