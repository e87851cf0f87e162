// libcloudbench_images.so: the operations of harness/report/images/ImageModule.h
// through OpenImageIO and OpenVDB. Nothing else in cloudbench includes either.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <openvdb/openvdb.h>
#include <sys/mman.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>

#include "harness/report/images/ImageModule.h"

namespace cb::images {
namespace {

OIIO::ImageSpec FloatSpec(const ImageView& image) {
    OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
    if (image.colorSpace && *image.colorSpace) spec.attribute("oiio:ColorSpace", image.colorSpace);
    return spec;
}

// Wraps the view's pixels, without copying; OpenImageIO only reads them here.
OIIO::ImageBuf Wrap(const ImageView& image) {
    return OIIO::ImageBuf(FloatSpec(image), const_cast<float*>(image.pixels));
}

FloatImage Copy(const OIIO::ImageBuf& buffer) {
    const OIIO::ImageSpec& spec = buffer.spec();
    FloatImage out{spec.width, spec.height, spec.nchannels, {}, spec.get_string_attribute("oiio:ColorSpace")};
    out.pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    buffer.get_pixels(buffer.roi(), OIIO::TypeDesc::FLOAT, out.pixels.data());
    return out;
}

// OIIO's errors on one line ("a; b"), as every "cannot write" message is: libpng's come in several.
std::string OneLine(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    for (size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at)) text.replace(at, 1, "; ");
    return text;
}

// OIIO's PNG writer can report success on a full disk, so the file is read
// back whole. ImageInput, not ImageBuf: the shared image cache could answer
// with an earlier file of the same name.
std::string Write(const std::string& path, const std::string& format, ImageView image, bool eightBit) {
    OIIO::ImageBuf buffer = Wrap(image);
    if (eightBit) buffer.set_write_format(OIIO::TypeDesc::UINT8);
    if (!buffer.write(path, OIIO::TypeUnknown, format)) return OneLine(buffer.geterror());
    auto in = OIIO::ImageInput::create(format);
    OIIO::ImageSpec got;
    std::vector<float> pixels(size_t(image.width) * size_t(image.height) * size_t(image.channels));
    const bool whole = in && in->open(path, got) && got.width == image.width && got.height == image.height &&
                       got.nchannels == image.channels &&
                       in->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::FLOAT, pixels.data());
    if (whole) return "";
    return "it does not read back whole (" + OneLine(in ? in->geterror() : OIIO::geterror()) + ")";
}

// The bytes go into an anonymous memory file (memfd), opened by its /proc/self/fd name: OpenImageIO 2.4's
// OpenEXR reader does not read through an IOProxy, and nothing on disk is opened again.
std::string Decode(const std::string& name, const std::string& bytes, int channels, FloatImage& image) {
    const int fd = ::memfd_create("cloudbench-image", MFD_CLOEXEC);
    if (fd < 0) return std::string("cannot hold the image in memory: ") + std::strerror(errno);
    std::string why;
    for (size_t done = 0; done < bytes.size() && why.empty();) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) why = std::string("cannot hold the image in memory: ") + std::strerror(n < 0 ? errno : EIO);
        done += n > 0 ? size_t(n) : 0;
    }
    const std::string memory = "/proc/self/fd/" + std::to_string(fd);
    const std::string extension = std::filesystem::path(name).extension().string();
    const std::string format = extension.empty() ? name : extension.substr(1);  // "exr", "png"
    auto in = why.empty() ? OIIO::ImageInput::create(format) : nullptr;
    OIIO::ImageSpec spec;
    if (why.empty() && !(in && in->open(memory, spec))) why = OneLine(in ? in->geterror() : OIIO::geterror());
    if (why.empty() && spec.nchannels < channels) why = "has " + std::to_string(spec.nchannels) + " channels, not RGB";
    if (why.empty()) {
        image = FloatImage{spec.width, spec.height, channels, {}, spec.get_string_attribute("oiio:ColorSpace")};
        image.pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(channels));
        if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
            why = OneLine(in->geterror());
    }
    if (in) in->close();
    ::close(fd);
    return why;
}

Comparison Compare(ImageView a, ImageView b, float limit, float tolerance) {
    const auto result = OIIO::ImageBufAlgo::compare(Wrap(a), Wrap(b), limit, tolerance);
    Comparison c;
    c.maxError = result.maxerror;
    c.meanError = result.meanerror;
    c.psnr = result.PSNR;
    c.pixelsOverTolerance = size_t(result.nfail + result.nwarn);
    c.worstX = result.maxx;
    c.worstY = result.maxy;
    return c;
}

std::string Difference(ImageView a, ImageView b, float gain, bool clamp, FloatImage& out) {
    OIIO::ImageBuf d = OIIO::ImageBufAlgo::absdiff(Wrap(a), Wrap(b));
    if (gain != 1) d = OIIO::ImageBufAlgo::mul(d, gain);
    if (clamp) d = OIIO::ImageBufAlgo::clamp(d, 0.0f, 1.0f);
    if (d.has_error()) return d.geterror();
    out = Copy(d);
    return "";
}

std::string LinearToSrgb(ImageView linear, FloatImage& srgb) {
    OIIO::ImageBuf converted;
    if (!OIIO::ImageBufAlgo::colorconvert(converted, Wrap(linear), "linear", "sRGB")) return converted.geterror();
    srgb = Copy(converted);
    return "";
}

std::string EncodePng(ImageView image, std::string& bytes) {
    std::vector<unsigned char> file;
    OIIO::Filesystem::IOVecOutput proxy(file);
    auto out = OIIO::ImageOutput::create("image.png", &proxy);
    if (!out) return "no PNG writer: " + OIIO::geterror();
    const OIIO::ImageBuf buffer = Wrap(image);
    OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::UINT8);
    std::vector<unsigned char> pixels(spec.image_bytes());
    if (!buffer.get_pixels(buffer.roi(), OIIO::TypeDesc::UINT8, pixels.data()) || !out->open("image.png", spec) ||
        !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) || !out->close())
        return "cannot encode: " + out->geterror();
    bytes.assign(file.begin(), file.end());
    return "";
}

std::string WriteVdb(const std::string& path, VolumeView volume) {
    try {
        openvdb::initialize();
        openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
        openvdb::FloatGrid::Accessor voxels = grid->getAccessor();
        size_t active = 0;
        for (unsigned k = 0; k < volume.nz; ++k)
            for (unsigned j = 0; j < volume.ny; ++j)
                for (unsigned i = 0; i < volume.nx; ++i) {
                    const float value = volume.values[i + size_t(volume.nx) * (j + size_t(volume.ny) * k)];
                    if (std::bit_cast<uint32_t>(value) == 0) continue;  // +0: the background
                    voxels.setValue(openvdb::Coord(int(i), int(j), int(k)), value);
                    ++active;
                }
        const double h = volume.voxelSize;
        openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(h);
        transform->postTranslate(
            openvdb::Vec3d(volume.origin[0] + 0.5 * h, volume.origin[1] + 0.5 * h, volume.origin[2] + 0.5 * h));
        grid->setTransform(transform);
        grid->setName(volume.name);
        grid->setGridClass(openvdb::GRID_FOG_VOLUME);
        openvdb::io::File file(path);
        file.write({grid});
        file.close();
        // Read back: the grid is there, whole.
        openvdb::io::File back(path);
        back.open();
        const openvdb::GridBase::Ptr read = back.readGrid(volume.name);
        back.close();
        if (!read || read->activeVoxelCount() != openvdb::Index64(active))
            return "it does not read back whole (" + std::to_string(read ? read->activeVoxelCount() : 0) + " of " +
                   std::to_string(active) + " voxels)";
        return "";
    } catch (const std::exception& e) {
        return std::string("OpenVDB: ") + e.what();
    }
}

const Module kModule{kModuleVersion, Write, Decode, Compare, Difference, LinearToSrgb, EncodePng, WriteVdb};

}  // namespace
}  // namespace cb::images

extern "C" __attribute__((visibility("default"))) const cb::images::Module* cloudbench_image_module() {
    return &cb::images::kModule;
}
