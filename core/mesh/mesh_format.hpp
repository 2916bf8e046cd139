// MeshFormat: the file formats we read, recognised by content first and by extension second.
#pragma once

#include <optional>
#include <string_view>

namespace salient::core {

enum class MeshFormat { stl_ascii, stl_binary, obj, ply, off };

std::string_view format_name(MeshFormat format);

// The format of `bytes`, from its content where that is conclusive, else from the extension of
// `file_name`; nullopt if neither tells.
std::optional<MeshFormat> detect_format(std::string_view bytes, std::string_view file_name);

}  // namespace salient::core
