// What a section reader's declaration needs (docs/scenes.md): the document and
// the validator, declared without nlohmann's full header. Each stage's module
// declares the reader of its section with these (core/stages/<stage>/).
#pragma once

#include <nlohmann/json_fwd.hpp>

namespace cb::scene_io {

using Json = nlohmann::ordered_json;  // as core/base/JsonDom.h
class Validator;                      // core/scene/SceneValidator.h

}  // namespace cb::scene_io
