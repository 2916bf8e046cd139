# The Debian package (`make deb`: cpack -G DEB in the build tree): install rules for the Debian
# layout and CPack's DEB generator. Included from the top CMakeLists.txt. Maintainer scripts,
# conffiles and the package's config are the files beside this one.
set(deb_dir "${PROJECT_SOURCE_DIR}/deploy/debian")

install(TARGETS salientd salient salient-sim RUNTIME DESTINATION bin)
# Absolute destinations: /etc, /lib and /var are not under the /usr prefix.
install(FILES "${deb_dir}/salientd.toml" DESTINATION /etc/salient)
install(FILES "${PROJECT_SOURCE_DIR}/deploy/systemd/salientd.service" DESTINATION /lib/systemd/system)
install(FILES "${PROJECT_SOURCE_DIR}/deploy/udev/60-salient-printers.rules" DESTINATION /lib/udev/rules.d)

# The version orders every commit: 0.1.0+git<commits>.<hash>, so a package built from a later
# commit upgrades one built from an earlier (dpkg compares the commit count first).
execute_process(COMMAND git -C "${PROJECT_SOURCE_DIR}" rev-list --count HEAD
                OUTPUT_VARIABLE git_count OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
execute_process(COMMAND git -C "${PROJECT_SOURCE_DIR}" rev-parse --short=8 HEAD
                OUTPUT_VARIABLE git_hash OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
set(deb_version "${PROJECT_VERSION}")
if(git_count AND git_hash)
  set(deb_version "${PROJECT_VERSION}+git${git_count}.${git_hash}")
endif()

# /usr/share/doc/salient: copyright, the changelog (a native package's: changelog.gz, gzip -9n:
# reproducible, as lintian asks), README.
set(doc_build "${PROJECT_BINARY_DIR}/deb-doc")
file(MAKE_DIRECTORY "${doc_build}")
string(TIMESTAMP deb_date "%a, %d %b %Y %H:%M:%S +0000" UTC)
file(READ "${deb_dir}/changelog" changelog)
string(REPLACE "@DEB_VERSION@" "${deb_version}" changelog "${changelog}")
string(REPLACE "@GIT_DESCRIBE@" "${git_hash}" changelog "${changelog}")
string(REPLACE "@DEB_DATE@" "${deb_date}" changelog "${changelog}")
file(WRITE "${doc_build}/changelog" "${changelog}")
execute_process(COMMAND gzip -9nf "${doc_build}/changelog")
foreach(page salientd salient salient-sim)
  configure_file("${deb_dir}/man/${page}.1" "${doc_build}/${page}.1" COPYONLY)
  execute_process(COMMAND gzip -9nf "${doc_build}/${page}.1")
  install(FILES "${doc_build}/${page}.1.gz" DESTINATION share/man/man1)
endforeach()
install(FILES "${doc_build}/changelog.gz" "${deb_dir}/copyright" "${PROJECT_SOURCE_DIR}/README.md"
        DESTINATION share/doc/salient)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME salient)
set(CPACK_PACKAGE_VERSION "${deb_version}")
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
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA "${deb_dir}/conffiles;${deb_dir}/postinst;${deb_dir}/prerm;${deb_dir}/postrm")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
