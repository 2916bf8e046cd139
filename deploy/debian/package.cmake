# The Debian package (`make deb`: cpack -G DEB in the build tree): install rules for the Debian
# layout and CPack's DEB generator. Included from the top CMakeLists.txt. Maintainer scripts,
# conffiles and the package's config are the files beside this one.
set(deb_dir "${PROJECT_SOURCE_DIR}/deploy/debian")

install(TARGETS salientd salient salient-sim RUNTIME DESTINATION bin)
# Absolute destinations: /etc, /lib and /var are not under the /usr prefix.
install(FILES "${deb_dir}/salientd.toml" DESTINATION /etc/salient)
install(FILES "${PROJECT_SOURCE_DIR}/deploy/systemd/salientd.service" DESTINATION /lib/systemd/system)
install(FILES "${PROJECT_SOURCE_DIR}/deploy/udev/60-salient-printers.rules" DESTINATION /lib/udev/rules.d)

# /usr/share/doc/salient: copyright, README, and the changelog, which cpack_config.cmake writes
# when cpack runs (with the version: both follow the commit the package is made from).
set(doc_build "${PROJECT_BINARY_DIR}/deb-doc")
file(MAKE_DIRECTORY "${doc_build}")
set(CPACK_SALIENT_SOURCE_DIR "${PROJECT_SOURCE_DIR}")
set(CPACK_SALIENT_DOC_DIR "${doc_build}")
set(CPACK_SALIENT_UPSTREAM_VERSION "${PROJECT_VERSION}")
set(CPACK_PROJECT_CONFIG_FILE "${deb_dir}/cpack_config.cmake")
foreach(page salientd salient salient-sim)
  configure_file("${deb_dir}/man/${page}.1" "${doc_build}/${page}.1" COPYONLY)
  execute_process(COMMAND gzip -9nf "${doc_build}/${page}.1")
  install(FILES "${doc_build}/${page}.1.gz" DESTINATION share/man/man1)
endforeach()
install(FILES "${deb_dir}/copyright" "${PROJECT_SOURCE_DIR}/README.md" DESTINATION share/doc/salient)
install(FILES "${PROJECT_SOURCE_DIR}/deploy/farm/api.toml" "${PROJECT_SOURCE_DIR}/deploy/farm/printers.toml"
        DESTINATION share/doc/salient/examples/farm)
# OPTIONAL: a plain `cmake --install` (no cpack) has no changelog to install.
install(FILES "${doc_build}/changelog.gz" DESTINATION share/doc/salient OPTIONAL)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME salient)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_PACKAGE_CONTACT "salient maintainers <salient@example.org>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "3D-printing service with saliency-preserving adaptive slicing")
# The first line of the Description is the summary above; CPack adds it.
string(CONCAT CPACK_DEBIAN_PACKAGE_DESCRIPTION
       "salientd is a print server for FDM printers: it chooses each layer's\n"
       "thickness from the visual saliency of the surface (thin layers where a viewer\n"
       "looks, thick layers elsewhere), slices, and streams the G-code to Marlin or\n"
       "Sailfish printers over USB serial. It serves a web page, a REST and WebSocket\n"
       "API, and OctoPrint's API for slicers and farm managers.\n"
       "salient is the command-line tool; salient-sim a simulated printer.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Beyond the libraries (shlibdeps): the page's JavaScript libraries, served from
# /usr/share/javascript; adduser for the maintainer scripts (deb-systemd-invoke is in
# init-system-helpers, which is essential).
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libjs-three, libjs-chart.js, adduser")
# The installed config announces the box over Zeroconf ([zeroconf]); without avahi-daemon it
# still runs and says so in the journal.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "avahi-daemon")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA "${deb_dir}/conffiles;${deb_dir}/postinst;${deb_dir}/prerm;${deb_dir}/postrm")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
