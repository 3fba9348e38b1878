# `cmake --install` and `cpack -G DEB`: rm3d in bin/, its data (module types, meshes, terrain
# images, lua/, behaviors/, worlds/, docs/ and its pictures) in share/rm3d/, where an installed rm3d looks first (app/data_root.h).
install(TARGETS rm3d RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
set(RM3D_DATA_DIR ${CMAKE_INSTALL_DATADIR}/rm3d)
# terrain: the heightfield images worlds/terrain.lua reads; readme: the pictures docs/ shows.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/assets/modules ${PROJECT_SOURCE_DIR}/assets/meshes
                  ${PROJECT_SOURCE_DIR}/assets/terrain ${PROJECT_SOURCE_DIR}/assets/readme
        DESTINATION ${RM3D_DATA_DIR}/assets)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lua ${PROJECT_SOURCE_DIR}/behaviors ${PROJECT_SOURCE_DIR}/worlds
                  ${PROJECT_SOURCE_DIR}/docs DESTINATION ${RM3D_DATA_DIR})
install(FILES ${PROJECT_SOURCE_DIR}/.luarc.json ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${RM3D_DATA_DIR}
        OPTIONAL)

# A Debian package: `cd build && cpack -G DEB` writes rm3d_<version>_<arch>.deb (installs under /usr).
set(CPACK_PACKAGE_NAME rm3d)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "physics-based simulator for self-reconfigurable modular robots")
set(CPACK_PACKAGE_CONTACT "RM3D maintainers <rm3d@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# Library dependencies from the binary (dpkg-shlibdeps, in dpkg-dev); ffmpeg for --video.
find_program(RM3D_DPKG_SHLIBDEPS dpkg-shlibdeps)
if(RM3D_DPKG_SHLIBDEPS)
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "ffmpeg")
set(CPACK_GENERATOR DEB)
include(CPack)
