# OpenVDB ships a find module (FindOpenVDB.cmake), not a package config, and Debian installs it in
# the multiarch library folder: /usr/lib/<triplet>/cmake/OpenVDB (x86_64-linux-gnu,
# aarch64-linux-gnu, ...). This finds that folder by CMake's own search over the prefixes, for the
# target's architecture, and puts it on CMAKE_MODULE_PATH; -DFREP_OPENVDB_MODULE_DIR=DIR chooses
# another. Included by the top-level project and by tests/fuzz (a project of its own).
include_guard(DIRECTORY)
include(GNUInstallDirs)
set(_frep_vdb_suffixes)
foreach(libdir IN ITEMS "lib/${CMAKE_LIBRARY_ARCHITECTURE}" "${CMAKE_INSTALL_LIBDIR}" lib lib64)
  list(APPEND _frep_vdb_suffixes "${libdir}/cmake/OpenVDB")
endforeach()
list(REMOVE_DUPLICATES _frep_vdb_suffixes)
# The prefixes CMake searches (CMAKE_PREFIX_PATH, the install prefix, /usr/local, /usr, ...) with
# each library folder of the target's architecture ...
find_path(FREP_OPENVDB_MODULE_DIR FindOpenVDB.cmake
          PATHS ${CMAKE_PREFIX_PATH} ${CMAKE_SYSTEM_PREFIX_PATH}
          PATH_SUFFIXES ${_frep_vdb_suffixes}
          NO_DEFAULT_PATH
          DOC "Folder of OpenVDB's FindOpenVDB.cmake")
# ... then any multiarch folder, when the compiler named no architecture.
if(NOT FREP_OPENVDB_MODULE_DIR)
  file(GLOB _frep_vdb_multiarch LIST_DIRECTORIES true /usr/lib/*/cmake/OpenVDB /usr/local/lib/*/cmake/OpenVDB)
  find_path(FREP_OPENVDB_MODULE_DIR FindOpenVDB.cmake PATHS ${_frep_vdb_multiarch} NO_DEFAULT_PATH)
endif()
if(NOT FREP_OPENVDB_MODULE_DIR)
  message(FATAL_ERROR "OpenVDB's FindOpenVDB.cmake not found (Debian: apt-get install libopenvdb-dev); "
                      "pass -DFREP_OPENVDB_MODULE_DIR=<folder holding it>")
endif()
list(APPEND CMAKE_MODULE_PATH "${FREP_OPENVDB_MODULE_DIR}")
unset(_frep_vdb_suffixes)
unset(_frep_vdb_multiarch)
