// The scratch a gl stage object owns (core/pipeline/StageObjects.h): textures
// and buffer objects kept between calls, made and resized by the façade
// (BackendGL::Scratch, ScratchBuffer) and deleted with the object that holds
// them, while the façade's context is still current.
#pragma once

#include <cstddef>
#include <utility>

#include "impl_gl/GLFunctions.h"

namespace cb::gl {

// A GL object name with the function that deletes it, owned by one slot.
template <void (*Delete)(const Functions&, GLuint)>
class OwnedName {
  public:
    OwnedName() = default;
    OwnedName(const OwnedName&) = delete;
    OwnedName& operator=(const OwnedName&) = delete;
    ~OwnedName() { Reset(); }
    GLuint Get() const { return mName; }
    // Deletes what the slot holds and takes `name`, to delete with `f`.
    void Reset(const Functions* f = nullptr, GLuint name = 0) {
        if (mName) Delete(*mF, mName);
        mF = f, mName = name;
    }
    void Swap(OwnedName& other) noexcept { std::swap(mF, other.mF), std::swap(mName, other.mName); }

  private:
    const Functions* mF = nullptr;
    GLuint mName = 0;
};

inline void DeleteTexture(const Functions& f, GLuint texture) { f.DeleteTextures(1, &texture); }
inline void DeleteBuffer(const Functions& f, GLuint buffer) { f.DeleteBuffers(1, &buffer); }

// A texture, remade by BackendGL::Scratch when its target, format or size changes.
struct TextureSlot {
    OwnedName<DeleteTexture> name;
    GLenum target = 0, format = 0;
    GLsizei width = 0, height = 0, depth = 0;
    // Exchanges two slots' textures (a ping-pong between steps).
    void Swap(TextureSlot& other) noexcept {
        name.Swap(other.name);
        std::swap(target, other.target), std::swap(format, other.format);
        std::swap(width, other.width), std::swap(height, other.height), std::swap(depth, other.depth);
    }
};

// A buffer object, grown by BackendGL::ScratchBuffer to the largest size asked of it.
struct BufferSlot {
    OwnedName<DeleteBuffer> name;
    size_t bytes = 0;
};

}  // namespace cb::gl
