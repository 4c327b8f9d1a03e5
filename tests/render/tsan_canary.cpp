// The ThreadSanitizer build's proof that it can still fail: after Embree has built and released a
// BVH (the work whose synchronisation tests/tsan.supp covers), two TBB tasks add to one plain int.
// TSan must report that race in this file; the `tsan` preset's test passes only if it does.

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>

int main() {
    // A BVH big enough for Embree to build it with TBB tasks.
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    RTCGeometry mesh = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    constexpr unsigned kTriangles = 200'000;
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * kTriangles));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), kTriangles));
    for (unsigned i = 0; i < kTriangles; ++i) {
        const float x = float(i % 500), y = float(i / 500);
        const float corners[9] = {x, y, 0, x + 1, y, 0, x, y + 1, 0};
        for (int k = 0; k < 9; ++k) v[9 * i + k] = corners[k];
        for (unsigned k = 0; k < 3; ++k) t[3 * i + k] = 3 * i + k;
    }
    rtcCommitGeometry(mesh);
    rtcAttachGeometry(scene, mesh);
    rtcReleaseGeometry(mesh);
    rtcCommitScene(scene);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);

    // The race: two tasks that each wait (up to 10 s) until the other has started, so that two
    // threads run them however busy the machine is, then both add to `sum` unsynchronised.
    // On the heap, freshly allocated: a stack slot may have held one of Embree's task-group
    // contexts, and TSan would pair the first write with TBB's stale access to that context (which
    // tests/tsan.supp suppresses) instead of with the other task's write.
    auto sum = std::make_unique<int>(0);
    std::atomic<int> started{0};
    tbb::task_arena two(2);
    two.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<int>(0, 2, 1),
            [&](const tbb::blocked_range<int>& r) {
                started.fetch_add(1);
                const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
                while (started.load() < 2 && std::chrono::steady_clock::now() < give_up)
                    std::this_thread::yield();
                for (int i = r.begin(); i != r.end(); ++i) *sum += i + 1;
            },
            tbb::simple_partitioner());
    });
    std::printf("sum %d\n", *sum);
    return 0;
}
