// 3MF: [Content_Types].xml, _rels/.rels, 3D/3dmodel.model (3MF core spec, millimetres) and the
// PrusaSlicer layer-height profile.
#include "core/export/three_mf.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/common/fixed_text.hpp"
#include "core/common/input_error.hpp"
#include "core/common/xml_escape.hpp"
#include "core/export/zip_writer.hpp"

namespace salient::core {
namespace {

std::string num(double v) {
  return fixed_text(v, 6);
}

}  // namespace

std::string prusa_layer_height_profile(const std::vector<double>& z) {
  std::string out = "object_id=1|";
  bool first = true;
  for (std::size_t i = 0; i + 1 < z.size(); ++i) {
    const double h = z[i + 1] - z[i];
    const double top = i + 2 < z.size() ? z[i + 1] - 1e-4 : z[i + 1];
    for (double at : {z[i], top}) {
      if (!first) out += ';';
      out += num(at);
      out += ';';
      out += num(h);
      first = false;
    }
  }
  return out + "\n";
}

std::string three_mf(const Mesh& mesh, const std::vector<double>& z, const std::string& object_name) {
  std::ostringstream model;
  model << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<model unit=\"millimeter\" xml:lang=\"en-US\" "
           "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n"
        << " <metadata name=\"Application\">salient</metadata>\n"
        << " <resources>\n  <object id=\"1\" name=\"" << xml_escape(object_name)
        << "\" type=\"model\">\n   <mesh>\n    <vertices>\n";
  for (const Vec3& p : mesh.positions)
    model << "     <vertex x=\"" << num(p.x) << "\" y=\"" << num(p.y) << "\" z=\"" << num(p.z) << "\"/>\n";
  model << "    </vertices>\n    <triangles>\n";
  for (const Triangle& t : mesh.triangles)
    model << "     <triangle v1=\"" << t[0] << "\" v2=\"" << t[1] << "\" v3=\"" << t[2] << "\"/>\n";
  model << "    </triangles>\n   </mesh>\n  </object>\n </resources>\n <build>\n  <item objectid=\"1\"/>\n "
           "</build>\n</model>\n";
  ZipWriter zip;
  zip.add(
      "[Content_Types].xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types "
      "xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">"
      "<Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>"
      "<Default Extension=\"model\" "
      "ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>\n");
  zip.add("_rels/.rels",
          "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships "
          "xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">"
          "<Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" "
          "Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>\n");
  zip.add("3D/3dmodel.model", model.str());
  zip.add("Metadata/Slic3r_PE_layer_heights_profile.txt", prusa_layer_height_profile(z));
  return zip.finish();
}

void write_three_mf(const std::filesystem::path& path, const Mesh& mesh, const std::vector<double>& z,
                    const std::string& object_name) {
  const std::string bytes = three_mf(mesh, z, object_name);
  const std::filesystem::path tmp = path.string() + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw InputError(path.filename().string(), {}, "cannot write");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace salient::core
