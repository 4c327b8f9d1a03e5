// Messages of rays between ranks (ray_message.h): groups round-trip exactly, and a message that is
// cut, padded, of another version or naming a slot past the last is refused whole, naming its
// sender.

#include "src/render/stream/ray_message.h"

#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

namespace nave::render {
namespace {

void ExpectError(const Status& status, StatusCode code, std::initializer_list<std::string> parts) {
    EXPECT_EQ(status.code(), code) << status.ToString();
    for (const std::string& p : parts)
        EXPECT_NE(status.message().find(p), std::string::npos)
            << status.message() << " lacks " << p;
}

std::vector<RayRecord> Rays(uint32_t first, uint32_t count) {
    std::vector<RayRecord> rays(count);
    for (uint32_t i = 0; i < count; ++i) {
        rays[i].pixel = first + i;
        rays[i].depth = uint16_t(i % 7);
        rays[i].origin = Vec3f(float(i), -float(i), 0.5f);
        // Wavelengths as camera paths draw them, some with their secondaries terminated (pdfs
        // that are not SampleVisible's: PackRayMessage must keep them too).
        rays[i].lambda = SampledWavelengths::SampleVisible(float(i % 13) / 13.f);
        if (i % 5 == 0) rays[i].lambda.TerminateSecondary();
    }
    return rays;
}

struct Group {
    uint32_t slot;
    std::vector<RayRecord> rays;
};

StatusOr<std::vector<Group>> Read(const std::vector<std::byte>& bytes, uint32_t slots) {
    std::vector<Group> groups;
    NAVE_ASSIGN_OR_RETURN(uint64_t rays,
                          ForEachRayGroup(bytes, slots, "rays from rank 3",
                                          [&](uint32_t slot, std::span<const RayRecord> g) {
                                              groups.push_back({slot, {g.begin(), g.end()}});
                                          }));
    uint64_t counted = 0;
    for (const Group& g : groups) counted += g.rays.size();
    if (counted != rays) return InternalError("{} rays visited, {} returned", counted, rays);
    return groups;
}

TEST(RayMessage, GroupsRoundTripByteForByte) {
    RayMessage message;
    const std::vector<RayRecord> a = Rays(0, 3), b = Rays(100, 1), c = Rays(200, 50);
    message.Append(4, a);
    message.Append(0, b);
    message.Append(4, {});  // nothing to send: no group
    message.Append(9, c);
    EXPECT_EQ(message.ray_count(), 54u);
    const std::vector<std::byte> bytes = message.Take();
    EXPECT_TRUE(message.empty());
    EXPECT_EQ(bytes.size(),
              kRayMessageHeaderBytes + 3 * kRayGroupHeaderBytes + 54 * sizeof(RayRecord));
    auto groups = Read(bytes, 10);
    ASSERT_TRUE(groups.ok()) << groups.status().ToString();
    ASSERT_EQ(groups->size(), 3u);
    const uint32_t slots[3] = {4, 0, 9};
    const std::vector<RayRecord>* sent[3] = {&a, &b, &c};
    for (int g = 0; g < 3; ++g) {
        EXPECT_EQ((*groups)[g].slot, slots[g]);
        ASSERT_EQ((*groups)[g].rays.size(), sent[g]->size());
        EXPECT_EQ(std::memcmp((*groups)[g].rays.data(), sent[g]->data(),
                              sent[g]->size() * sizeof(RayRecord)),
                  0);
    }
    // The message taken, the next starts empty.
    message.Append(1, b);
    auto next = Read(message.Take(), 10);
    ASSERT_TRUE(next.ok());
    ASSERT_EQ(next->size(), 1u);
    EXPECT_EQ((*next)[0].slot, 1u);
}

TEST(RayMessage, DamagedMessagesAreRefusedWholeNamingTheSender) {
    RayMessage message;
    message.Append(2, Rays(0, 4));
    message.Append(5, Rays(10, 2));
    const std::vector<std::byte> good = message.Take();
    ASSERT_TRUE(Read(good, 6).ok());

    std::vector<std::byte> cut(good.begin(), good.end() - 1);
    ExpectError(Read(cut, 6).status(), StatusCode::kDataLoss,
                {"rays from rank 3", "group 1", "2 rays", "message ends"});
    std::vector<std::byte> padded = good;
    padded.push_back(std::byte{0});
    ExpectError(Read(padded, 6).status(), StatusCode::kDataLoss,
                {"rays from rank 3", "1 bytes past the last of 2 groups"});
    std::vector<std::byte> version = good;
    version[0] = std::byte{7};
    ExpectError(Read(version, 6).status(), StatusCode::kDataLoss,
                {"rays from rank 3", "message version 7", "expected 1"});
    ExpectError(Read(good, 5).status(), StatusCode::kDataLoss,
                {"rays from rank 3", "brick slot 5", "expected < 5"});
    ExpectError(Read(std::vector<std::byte>(3), 6).status(), StatusCode::kDataLoss,
                {"rays from rank 3", "3 bytes"});
    // Nothing was visited from a refused message.
    int visited = 0;
    (void)ForEachRayGroup(cut, 6, "x", [&](uint32_t, std::span<const RayRecord>) { ++visited; });
    EXPECT_EQ(visited, 0);
}

// Packed for the wire (records transposed byte by byte, then LZ4), a message unpacks to the same
// bytes, and rays alike in most of their bytes, as a batch of one brick's rays is, take a few
// times fewer bytes.
TEST(RayMessage, PackedMessagesUnpackToTheSameBytesAndAreSmaller) {
    RayMessage message;
    message.Append(3, Rays(1000, 700));
    message.Append(1, Rays(5000, 1));
    message.Append(7, Rays(9000, 300));
    const std::vector<std::byte> raw = message.Take();
    const std::vector<std::byte> packed = PackRayMessage(raw);
    EXPECT_TRUE(IsPackedRayMessage(packed));
    EXPECT_FALSE(IsPackedRayMessage(raw));
    EXPECT_LT(packed.size() * 3, raw.size()) << "similar rays should pack at least 3x";
    std::vector<std::byte> unpacked;
    const Status status = UnpackRayMessage(packed, raw.size(), "rays from rank 3", &unpacked);
    ASSERT_TRUE(status.ok()) << status.ToString();
    ASSERT_EQ(unpacked.size(), raw.size());
    EXPECT_EQ(std::memcmp(unpacked.data(), raw.data(), raw.size()), 0);
    // An empty message too.
    const std::vector<std::byte> none = RayMessage().Take();
    ASSERT_TRUE(UnpackRayMessage(PackRayMessage(none), 64, "x", &unpacked).ok());
    EXPECT_EQ(unpacked, none);
}

TEST(RayMessage, DamagedPackedMessagesAreRefusedNamingTheSender) {
    RayMessage message;
    message.Append(2, Rays(0, 40));
    const std::vector<std::byte> raw = message.Take();
    const std::vector<std::byte> packed = PackRayMessage(raw);
    std::vector<std::byte> out;
    ExpectError(UnpackRayMessage(packed, raw.size() - 1, "rays from rank 3", &out),
                StatusCode::kDataLoss, {"rays from rank 3", "unpacks to", "at most"});
    std::vector<std::byte> cut(packed.begin(), packed.end() - 5);
    ExpectError(UnpackRayMessage(cut, raw.size(), "rays from rank 3", &out), StatusCode::kDataLoss,
                {"rays from rank 3", "does not unpack"});
    ExpectError(UnpackRayMessage(raw, raw.size(), "rays from rank 3", &out), StatusCode::kDataLoss,
                {"rays from rank 3", "not a packed ray message"});
    // A raw message whose group does not fit unpacks to bytes ForEachRayGroup refuses.
    std::vector<std::byte> short_raw(raw.begin(), raw.end() - 128);
    ASSERT_TRUE(UnpackRayMessage(PackRayMessage(short_raw), raw.size(), "x", &out).ok());
    ExpectError(Read(out, 6).status(), StatusCode::kDataLoss, {"group 0", "message ends"});
}

}  // namespace
}  // namespace nave::render
