# src/io: output folder, results (HDF5 + XDMF + CSV + JSON), checkpoints, atomic files, HDF5 RAII.
# Included from src/CMakeLists.txt.
target_sources(capsflow_core PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/io/atomic_file.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/io/checkpoint.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/io/h5.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/io/output_folder.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/io/results_writer.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/io/timeseries_csv.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/io/xdmf.cpp
)
