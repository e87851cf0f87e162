#include "core/Backend.h"

namespace cb {

size_t CanonicalElementBytes(BufferFormat format) { return format == BufferFormat::F32 ? 4 : 1; }

}  // namespace cb
