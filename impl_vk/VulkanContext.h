// The Vulkan objects a backend needs: instance, one device and its compute
// queue, memory, compute pipelines from the build's SPIR-V, and submission with
// timestamp queries: synchronous per call, or recorded into one command buffer
// per batch (BeginBatch .. EndBatch, core/pipeline/Backend.h "Pipelined timing"). Every
// Vulkan call is checked and its failure says what was being done (CheckVk).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/base/Error.h"

namespace cb::vk {

// "doing X: VK_ERROR_..." for a failed call.
Status CheckVk(VkResult result, const char* what);

struct DeviceInfo {
    uint32_t index;
    std::string name;
    std::string type;  // "cpu", "integrated GPU", "discrete GPU", ...
    uint32_t apiVersion;
    std::string driver;  // driver name and version info ("llvmpipe Mesa 22.3.6"); "?" before Vulkan 1.2
    VkPhysicalDeviceLimits limits{};  // vkGetPhysicalDeviceProperties' limits
};

// The Vulkan devices on this machine; an Error says why there are none.
Result<std::vector<DeviceInfo>> ListDevices();

// A device-local storage buffer.
struct DeviceBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
};

// Which variant of a pipeline a call dispatches: the whole grid, or a share of
// it (time-slicing). An enum, not a bool, so that a SPIR-V array never
// converts to it in GetPipeline's overloads.
enum class PipelineRange : uint8_t { Whole, Share };

// One compute pipeline: N storage buffers at bindings 0..N-1 and up to 128
// bytes of push constants.
struct Pipeline {
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    uint32_t bindings = 0;
    bool ranged = false;  // the share variant: DISPATCH_BASE_BIT and kRanged = true (GetPipeline)
};

class VulkanContext {
  public:
    // device: an index, a substring of the device name, or "" for the first.
    // validation: enable VK_LAYER_KHRONOS_validation and count its messages.
    static Result<std::unique_ptr<VulkanContext>> Create(const std::string& device, bool validation);
    ~VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;

    const std::string& DeviceName() const { return mDeviceName; }
    // The device's limits (vkGetPhysicalDeviceProperties), read when the context is made.
    const VkPhysicalDeviceLimits& DeviceLimits() const { return mLimits; }
    // Whether the device is the host's CPU (lavapipe): dispatches are cheap there, cells dear.
    bool CpuDevice() const { return mCpuDevice; }
    uint32_t ValidationMessages() const { return mValidationMessages; }

    // A device-local storage buffer of StorageBufferBytes(size) bytes.
    Result<DeviceBuffer> CreateBuffer(VkDeviceSize size);
    // The size CreateBuffer allocates for `size` bytes: padded to a multiple of 4
    // (uint8 volumes are read as bytes).
    static VkDeviceSize StorageBufferBytes(VkDeviceSize size) { return (size + 3) & ~VkDeviceSize(3); }
    // The size of the largest device-local memory heap.
    VkDeviceSize LargestDeviceLocalHeap() const;
    // Destroys the buffer now, or, while commands are recorded and not yet
    // complete, once they are (a scratch slot that grows in a batch).
    void DestroyBuffer(DeviceBuffer& buffer);
    // Outside a batch: copies through a host-visible buffer, submits and waits.
    // In a batch, Upload copies the bytes into the batch's host-visible arena
    // now and records a device copy plus a barrier, so that it keeps its order
    // with the recorded commands; Download records the copy, submits what is
    // recorded, waits (a counted host wait), reads, and the batch continues in
    // a fresh command buffer.
    Status Upload(const DeviceBuffer& buffer, std::span<const std::byte> data);
    Status Download(const DeviceBuffer& buffer, std::span<std::byte> data);
    // In a batch: records a copy of the first `bytes` of `buffer` into the
    // batch's host-visible arena and gives them to `done` after the batch's
    // next wait (EndBatch's, or an earlier one), without a wait of its own
    // (deferred host results, core/pipeline/Backend.h). Outside a batch: a Download,
    // then `done`.
    using ReadDone = std::function<void(std::span<const std::byte>)>;
    Status DownloadLater(const DeviceBuffer& buffer, VkDeviceSize bytes, ReadDone done);

    // ---- Batches (core/pipeline/Backend.h, "Pipelined timing") ----
    // BeginBatch starts interval 0; MarkBatch the next one. Between BeginBatch
    // and EndBatch, Run records (each call bracketed by a timestamp pair of the
    // current interval and followed by a barrier that orders it before every
    // later command) and returns 0 ms; EndBatch submits once, waits once and
    // returns the device ms of each interval (empty without timestamps). When
    // the timestamp pairs of one submission run out (kBatchStampPairs), the
    // batch submits what it has and waits (counted) before going on.
    Status BeginBatch();
    void MarkBatch();
    Result<std::vector<double>> EndBatch();
    bool InBatch() const { return mInBatch; }
    // The MarkBatch() calls since BeginBatch: the mark of a call recorded now.
    uint32_t Interval() const { return mInterval; }
    static constexpr uint32_t kBatchStampPairs = 1024;
    // Cumulative: vkQueueSubmit calls, and host blocks on the device (fence
    // waits; the query reads follow a fence wait and never block).
    uint64_t Submissions() const { return mSubmissions; }
    uint64_t HostWaits() const { return mHostWaits; }
    // Cumulative: dispatches recorded (the per-dispatch overhead).
    uint64_t Dispatches() const { return mDispatches; }

    // The pipeline of a shader compiled into the build (impl_vk/shaders/<name>.comp).
    // PipelineRange::Share: the variant for shares (SPEC 13): made with VK_PIPELINE_CREATE_DISPATCH_BASE_BIT
    // and the shader's specialisation constant 0 (`kRanged`, a bool) true, so that it
    // tests both ends of [first, end) and may start at a base workgroup
    // (Recorder::DispatchRange); the plain variant is the whole call's.
    Result<Pipeline*> GetPipeline(const std::string& name, uint32_t bindings,
                                  PipelineRange range = PipelineRange::Whole);
    // The pipeline of SPIR-V compiled elsewhere (tests), cached under `name`.
    Result<Pipeline*> GetPipeline(const std::string& name, uint32_t bindings, std::span<const uint32_t> spirv);

    // Records with `record`; outside a batch submits, waits and returns the
    // device time between its timestamp pair in ms; in a batch returns 0.
    class Recorder {
      public:
        // Binds `buffers` to a fresh descriptor set and dispatches ceil(invocations/64) groups.
        void Dispatch(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers, const void* push,
                      uint32_t pushBytes, uint32_t invocations);
        // The groups of 64 that hold invocations [first, end), from group first / 64 on
        // (vkCmdDispatchBase, so gl_GlobalInvocationID keeps its whole-dispatch value);
        // the shader returns for ids outside [first, end). With first = 0 a plain dispatch.
        // The pipeline must be ranged (GetPipeline) unless first < 64.
        void DispatchRange(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers, const void* push,
                           uint32_t pushBytes, uint32_t first, uint32_t end);
        // The same with an explicit grid of workgroups (shaders with 2-D workgroups).
        void DispatchGroups(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers, const void* push,
                            uint32_t pushBytes, uint32_t groupsX, uint32_t groupsY, uint32_t groupsZ);
        // Makes every earlier shader write visible to later shader reads and writes.
        void Barrier();
        void Fill(const DeviceBuffer& buffer, uint32_t value);
        // Copies `bytes` from `from` at `fromOffset` to `to` at `toOffset`, after every
        // earlier write; a later Barrier() or the segment's end orders it before what follows.
        void Copy(const DeviceBuffer& from, VkDeviceSize fromOffset, const DeviceBuffer& to, VkDeviceSize toOffset,
                  VkDeviceSize bytes);

      private:
        friend class VulkanContext;
        explicit Recorder(VulkanContext& context, VkCommandBuffer cmd) : mContext(context), mCmd(cmd) {}
        // Binds the pipeline, a fresh descriptor set of `buffers` and the push constants;
        // false (the error kept for EndSegment) when no set could be had.
        bool Bind(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers, const void* push,
                  uint32_t pushBytes);
        VulkanContext& mContext;
        VkCommandBuffer mCmd;
    };
    template <typename Fn>
    Result<double> Run(const char* what, Fn&& record) {
        CB_TRY(BeginSegment(what));
        Recorder recorder(*this, mCmd);
        record(recorder);
        return EndSegment(what);
    }

  private:
    VulkanContext() = default;
    // Begins the command buffer unless it is recording.
    Status EnsureRecording(const char* what);
    // Ensures recording and a free timestamp pair (submitting first when a
    // batch has used them all) and writes the pair's first stamp.
    Status BeginSegment(const char* what);
    // Writes the pair's second stamp; in a batch records the barrier after the
    // segment and returns 0, else submits, waits and returns the pair's ms.
    Result<double> EndSegment(const char* what);
    // Records a copy of `bytes` of `from` to `to` at `offset`, made visible to the
    // host, as one segment (in a batch, read after the next wait).
    Status RecordCopyToHost(const DeviceBuffer& from, const DeviceBuffer& to, VkDeviceSize offset, VkDeviceSize bytes,
                            const char* what);
    // Submits what is recorded, waits, adds the timestamps to their intervals,
    // then frees what the submission needed (descriptor sets, arena, retired buffers).
    Status Flush(const char* what);
    // A barrier from every earlier transfer and shader write to every later
    // transfer and shader access.
    void RecordFullBarrier();
    // A fresh descriptor set; a further pool when the current one is full.
    Result<VkDescriptorSet> AllocateSet(VkDescriptorSetLayout layout);
    Status AddDescriptorPool();
    // `size` bytes of host-visible arena for an upload in a batch: the buffer and offset.
    Result<std::pair<const DeviceBuffer*, VkDeviceSize>> ArenaSpace(VkDeviceSize size, void*& mapped);
    Result<Pipeline*> CreatePipeline(const std::string& name, uint32_t bindings, std::span<const uint32_t> spirv,
                                     bool ranged);
    Result<DeviceBuffer> CreateRawBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags properties);
    Status EnsureStaging(VkDeviceSize size);

    static VKAPI_ATTR VkBool32 VKAPI_CALL OnValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                              VkDebugUtilsMessageTypeFlagsEXT type,
                                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                              void* user);

    VkInstance mInstance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT mMessenger = VK_NULL_HANDLE;
    VkPhysicalDevice mPhysical = VK_NULL_HANDLE;
    VkDevice mDevice = VK_NULL_HANDLE;
    VkQueue mQueue = VK_NULL_HANDLE;
    uint32_t mQueueFamily = 0;
    VkCommandPool mPool = VK_NULL_HANDLE;
    VkCommandBuffer mCmd = VK_NULL_HANDLE;
    VkFence mFence = VK_NULL_HANDLE;
    VkQueryPool mQueries = VK_NULL_HANDLE;
    // Descriptor pools: sets come from pool mDescriptorPool on; all are reset after each wait.
    std::vector<VkDescriptorPool> mDescriptors;
    size_t mDescriptorPool = 0;
    VkPhysicalDeviceMemoryProperties mMemory{};
    float mTimestampPeriodNs = 1;
    bool mTimestamps = false;
    std::string mDeviceName;
    VkPhysicalDeviceLimits mLimits{};
    uint32_t mValidationMessages = 0;
    DeviceBuffer mStaging;
    VkDeviceMemory mStagingMemory = VK_NULL_HANDLE;
    void* mStagingMap = nullptr;
    std::map<std::string, Pipeline> mPipelines;

    // Submission state: the command buffer is recording; its timestamp pairs so
    // far and the interval of each; buffers to destroy once it completes.
    bool mRecording = false;
    std::vector<uint32_t> mPairInterval;
    double mLastPairMs = 0;
    std::vector<DeviceBuffer> mRetired;
    // A failure while recording (a descriptor set that could not be had), reported by EndSegment.
    std::optional<Error> mRecordError;
    // Batch state.
    bool mInBatch = false;
    uint32_t mInterval = 0;
    bool mCpuDevice = false;
    uint64_t mDispatches = 0;
    // DownloadLater's copies waiting for the next wait: arena bytes and who gets them.
    struct LaterRead {
        const void* mapped = nullptr;
        VkDeviceSize bytes = 0;
        ReadDone done;
    };
    std::vector<LaterRead> mLaterReads;
    std::vector<double> mIntervalMs;
    struct ArenaChunk {
        DeviceBuffer buffer;
        void* mapped = nullptr;
    };
    std::vector<ArenaChunk> mArena;
    size_t mArenaChunk = 0;
    VkDeviceSize mArenaOffset = 0;
    uint64_t mSubmissions = 0, mHostWaits = 0;
};

}  // namespace cb::vk
