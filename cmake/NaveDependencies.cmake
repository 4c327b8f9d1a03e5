# Finds every third-party library nave uses, as Debian 12 packages them. scripts/setup-debian.sh installs them.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(TBB REQUIRED)
if(NAVE_SANITIZE_THREAD AND NOT TBB_DIR MATCHES "tbb-tsan")
  # TBB hands a task to another thread inside libtbb: ThreadSanitizer sees that hand-off only in an
  # instrumented libtbb, and without it reports every parallel_for as a race.
  message(FATAL_ERROR "ThreadSanitizer needs a TBB built with -fsanitize=thread; found ${TBB_DIR}. "
                      "Run scripts/test.sh tsan (it builds Debian's oneTBB with TSan into build/deps/tbb-tsan).")
endif()
find_package(embree 3 REQUIRED)                  # target: embree
find_package(draco REQUIRED)                     # target: draco::draco
find_package(OpenImageIO REQUIRED)               # target: OpenImageIO::OpenImageIO
find_package(tomlplusplus REQUIRED)              # target: tomlplusplus::tomlplusplus
find_package(CLI11 REQUIRED)                     # target: CLI11::CLI11
find_package(spdlog REQUIRED)                    # target: spdlog::spdlog
find_package(fmt REQUIRED)                       # target: fmt::fmt
find_package(TinyGLTF REQUIRED)                  # target: TinyGLTF::TinyGLTF
find_package(assimp REQUIRED)                    # target: assimp::assimp
find_package(meshoptimizer REQUIRED)             # target: meshoptimizer::meshoptimizer
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
# jemalloc: the `nave` executable's allocator (glibc's heap fragments under paging: docs/pager.md, "Memory").
pkg_check_modules(JEMALLOC REQUIRED IMPORTED_TARGET jemalloc)

# OpenImageIO's exported target names /usr/include/opencv4, which exists only when OpenCV is installed.
foreach(prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
  get_target_property(dirs OpenImageIO::OpenImageIO ${prop})
  if(dirs)
    list(FILTER dirs EXCLUDE REGEX "opencv4")
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${prop} "${dirs}")
  endif()
endforeach()

# OpenVDB (the density grids of participating media, in the plugin src/volumes/vdb) ships only a
# Find module on Debian.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)

# MPI (Open MPI in Debian: libopenmpi-dev, openmpi-bin): the distributed render. Optional: without it
# nave is one process (docs/distributed.md).
find_package(MPI COMPONENTS CXX QUIET)
if(MPI_CXX_FOUND)
  message(STATUS "nave: MPI ${MPI_CXX_VERSION} found: building the distributed render")
else()
  message(STATUS "nave: MPI not found: nave renders as one process")
endif()

# Open CASCADE (libocct-data-exchange-dev, libocct-modeling-algorithms-dev): STEP and IGES files, in
# the plugin preprocess/import/cad. Optional: without it those formats are off and nave says so.
find_package(OpenCASCADE CONFIG QUIET)
if(OpenCASCADE_FOUND)
  message(STATUS "nave: Open CASCADE ${OpenCASCADE_VERSION} found: STEP and IGES import on")
  # The toolkits nave calls, by their files rather than Open CASCADE's imported targets: those carry
  # the link interface of its visualization (fontconfig, GL, X11, FreeImage) into every link, which
  # would need those libraries' -dev packages; at run time each toolkit finds its own dependencies.
  set(NAVE_OCCT_TOOLKITS)
  foreach(toolkit TKXDESTEP TKXDEIGES TKSTEP TKIGES TKXSBase TKXCAF TKLCAF TKCAF TKRWMesh TKMesh
                  TKPrim TKTopAlgo TKBRep TKGeomBase TKG3d TKG2d TKMath TKernel)
    list(APPEND NAVE_OCCT_TOOLKITS ${OpenCASCADE_LIBRARY_DIR}/lib${toolkit}.so)
  endforeach()
else()
  message(STATUS "nave: Open CASCADE not found: STEP and IGES import off (scripts/setup-debian.sh installs it)")
endif()

# IFC++ (libifcplusplus-dev: a reader of IFC 2x3 and 4 with Carve's geometry), in the plugin
# preprocess/import/ifc. Debian ships no CMake or pkg-config file for it. Optional: without it .ifc
# files go to Assimp, which reads some IFC 2x3.
find_path(IFCPP_INCLUDE_DIR ifcpp/reader/ReaderSTEP.h)
find_library(IFCPP_LIBRARY IfcPlusPlus PATH_SUFFIXES ifcplusplus)
find_library(CARVE_LIBRARY carve PATH_SUFFIXES ifcplusplus)
if(IFCPP_INCLUDE_DIR AND IFCPP_LIBRARY AND CARVE_LIBRARY)
  set(NAVE_HAVE_IFCPP ON)
  message(STATUS "nave: IFC++ found (${IFCPP_LIBRARY}): IFC import on")
else()
  set(NAVE_HAVE_IFCPP OFF)
  message(STATUS "nave: IFC++ not found: IFC files go to Assimp (scripts/setup-debian.sh installs IFC++)")
endif()

if(NAVE_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(NAVE_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
