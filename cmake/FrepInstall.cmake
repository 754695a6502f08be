# `cmake --install build [--prefix P]`: the libraries frep_core, frep_lang and frep_io (static,
# position-independent so that the Python module can take them in), their public headers, the
# frep and frep-worker programs, the man page and bash completion, a CMake package (find_package(frepfarm) -> frepfarm::core,
# frepfarm::lang, frepfarm::io) and a pkg-config file (frepfarm.pc). tests/consumer builds a
# small project against an installed tree both ways.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set_target_properties(frep_core frep_lang_archive frep_io PROPERTIES POSITION_INDEPENDENT_CODE ON)
set_target_properties(frep_core PROPERTIES EXPORT_NAME core)
set_target_properties(frep_io PROPERTIES EXPORT_NAME io)
# The archive keeps the library's name on disk (libfrep_lang.a); frepfarm::lang links it whole
# (its functions register themselves at static-init time, lang/CMakeLists.txt).
set_target_properties(frep_lang_archive PROPERTIES EXPORT_NAME lang_archive OUTPUT_NAME frep_lang)
set_target_properties(frep_lang PROPERTIES EXPORT_NAME lang)

set(FREP_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/frepfarm)
install(TARGETS frep_core frep_lang_archive frep_lang frep_io EXPORT frepfarmTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS frep frep-worker RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The modules the programs load when a job needs them (frep/io/program_module.h).
install(TARGETS frep_vdb frep_mesh_files frep_view LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/frepfarm)
install(DIRECTORY core/include/ lang/include/ io/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
# The man page (man 1 frep) and the bash completion, where bash-completion loads a command's
# completion on demand (share/bash-completion/completions/frep).
install(FILES docs/frep.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
install(FILES deploy/completion/frep.bash DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions
        RENAME frep)

install(EXPORT frepfarmTargets NAMESPACE frepfarm:: DESTINATION ${FREP_CMAKE_DIR})
# OpenVDB ships a find module, not a package config: the config file looks where it was found
# (FREP_OPENVDB_MODULE_DIR, cmake/FrepOpenVDB.cmake).
configure_package_config_file(cmake/frepfarmConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/frepfarmConfig.cmake
                              INSTALL_DESTINATION ${FREP_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/frepfarmConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/frepfarmConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/frepfarmConfigVersion.cmake
        DESTINATION ${FREP_CMAKE_DIR})

# The .pc file finds the prefix from its own place (relocatable): one ".." per part of
# lib/pkgconfig.
string(REGEX REPLACE "[^/]+" ".." FREP_PC_UP "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
configure_file(cmake/frepfarm.pc.in ${CMAKE_CURRENT_BINARY_DIR}/frepfarm.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/frepfarm.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
