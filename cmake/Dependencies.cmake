# Every third-party dependency is found here, once. The Debian packages that provide them are
# listed in scripts/apt-packages.txt.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs)
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(tomlplusplus REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(cppzmq REQUIRED)  # brings libzmq as its dependency
pkg_check_modules(gpiod REQUIRED IMPORTED_TARGET libgpiod)
pkg_check_modules(fftw3f REQUIRED IMPORTED_TARGET fftw3f)
pkg_check_modules(aravis REQUIRED IMPORTED_TARGET aravis-0.8)
pkg_check_modules(httplib REQUIRED IMPORTED_TARGET cpp-httplib)  # the dashboard's HTTP server
# MPI (OpenMPI, C API) for `mpirun tomorig process`. Listed in scripts/apt-packages.txt, so it is
# there on a machine set up by scripts/setup.sh; a build without it still works as one process and
# refuses to run under mpirun with a message saying so.
find_package(MPI COMPONENTS C)
if(MPI_C_FOUND)
  set(TOMORIG_WITH_MPI 1)
else()
  set(TOMORIG_WITH_MPI 0)
  message(STATUS "MPI not found (install libopenmpi-dev): tomorig process runs as one process only")
endif()
if(TOMORIG_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(TOMORIG_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# HDF5's CMake config on Debian exposes variables, not a target; wrap them once.
if(NOT TARGET tomorig::hdf5)
  add_library(tomorig_hdf5 INTERFACE)
  target_include_directories(tomorig_hdf5 SYSTEM INTERFACE ${HDF5_INCLUDE_DIRS})
  target_link_libraries(tomorig_hdf5 INTERFACE ${HDF5_C_LIBRARIES})
  target_compile_definitions(tomorig_hdf5 INTERFACE ${HDF5_DEFINITIONS})
  add_library(tomorig::hdf5 ALIAS tomorig_hdf5)
endif()
