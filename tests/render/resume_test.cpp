// A render stopped after some passes (or iterations) and resumed from its checkpoint ends with the
// same film, bit for bit, as the same render in one run: path mode with the path guide learning
// across the stop, photon mode with its radii, density sums and photon guides. One thread and the
// fullest brick always first, so that the film sums its samples in the same order in both.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "render_test_util.h"
#include "src/core/byte_stream.h"
#include "src/render/bricks/procedural_scenes.h"
#include "src/render/film/checkpoint.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_session.h"
#include "src/render/integrators/render_streams.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/scene_config.h"

namespace nave::render {
namespace {

const std::string kConfigs = std::string(NAVE_TEST_FIXTURES) + "/../../configs/";

using testing::RenderResult;

class ResumeTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_resume_test_" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    /// Loads `procedural` with config `config_file`, changed by `edit`, for one run.
    void Load(const std::string& procedural, const std::string& config_file,
              void (*edit)(SceneConfig*)) {
        auto device = EmbreeDevice::Create();
        ASSERT_TRUE(device.ok());
        auto source = OpenProceduralSource(procedural, *device);
        ASSERT_TRUE(source.ok()) << source.status().ToString();
        auto config = LoadSceneConfig(kConfigs + config_file);
        ASSERT_TRUE(config.ok()) << config.status().ToString();
        config->render.threads = 1;
        edit(&*config);
        auto scene = testing::BuildTestScene(std::move(*source), std::move(*config));
        ASSERT_TRUE(scene.ok()) << scene.status().ToString();
        scene_ = std::move(*scene);
    }

    /// Loads `mesh` (materials named `names`, cut into 2 x 2 x 2 bricks) with config `text`.
    void LoadMesh(const store::BrickMesh& mesh, const std::vector<std::string>& names,
                  const std::string& text) {
        auto config = ParseSceneConfig(text, "mesh.toml");
        ASSERT_TRUE(config.ok()) << config.status().ToString();
        config->render.threads = 1;
        auto scene = testing::BuildTestScene(
            testing::GridSource(mesh, testing::NamedMaterials(names), {2, 2, 2}),
            std::move(*config));
        ASSERT_TRUE(scene.ok()) << scene.status().ToString();
        scene_ = std::move(*scene);
    }

    /// One run with `options`, into a fresh film.
    RenderResult Render(const SessionOptions& options) {
        // The fullest brick first, whether resident or not: the order of the batches, and so of the
        // film's additions, does not depend on when background loads finish.
        testing::RunOptions run;
        run.picker = PickFullestBrick;
        run.session = &options;
        RenderResult r = scene_->Run(run);
        EXPECT_TRUE(r.status.ok()) << r.status.ToString();
        return r;
    }

    SessionOptions Options(const std::string& checkpoint_name) const {
        SessionOptions o;
        o.checkpoint_path = dir_ / checkpoint_name;
        o.checkpoint_every_s = 0;
        o.identity.mode = uint8_t(scene_->config.render.mode);
        return o;
    }

    static std::string FilmBytes(const Film& film) {
        ByteWriter w;
        film.SaveState(&w);
        return w.Take();
    }

    /// Renders in one run, then in runs of `stops` passes each resumed from the last one's
    /// checkpoint, and expects the same films and final checkpoint state.
    void ExpectResumedEqualsUninterrupted(std::initializer_list<int> stops, int total) {
        const RenderResult whole = Render(Options("whole.ckpt"));
        ASSERT_EQ(whole.stats.samples_per_pixel, total);
        std::unique_ptr<Checkpoint> resume;
        RenderResult last;
        int done = 0;
        for (int stop : stops) {
            SessionOptions o = Options("parts.ckpt");
            o.stop_after = stop;
            if (resume) {
                o.resume = resume.get();
                o.resume_name = o.checkpoint_path.string();
            }
            last = Render(o);
            done += stop;
            ASSERT_EQ(last.stats.samples_per_pixel, done);
            auto read = ReadCheckpoint(o.checkpoint_path);
            ASSERT_TRUE(read.ok()) << read.status().ToString();
            ASSERT_EQ(read->done, uint32_t(done));
            resume = std::make_unique<Checkpoint>(std::move(*read));
            // A stopped run's image is that of the passes so far: not yet the whole render's.
            EXPECT_NE(FilmBytes(*last.film), FilmBytes(*whole.film));
        }
        SessionOptions o = Options("parts.ckpt");
        o.resume = resume.get();
        o.resume_name = o.checkpoint_path.string();
        last = Render(o);
        ASSERT_EQ(last.stats.samples_per_pixel, total);
        EXPECT_TRUE(FilmBytes(*last.film) == FilmBytes(*whole.film))
            << "the resumed render's film differs from the uninterrupted one's";
        EXPECT_EQ(last.film->samples_per_pixel(), whole.film->samples_per_pixel());
        // Their last checkpoints hold the same state too (the guide's included).
        auto a = ReadCheckpoint(dir_ / "whole.ckpt");
        auto b = ReadCheckpoint(dir_ / "parts.ckpt");
        ASSERT_TRUE(a.ok() && b.ok());
        EXPECT_EQ(a->done, b->done);
        EXPECT_TRUE(a->sections == b->sections) << "the final checkpoints' state differs";
    }

    std::filesystem::path dir_;
    std::unique_ptr<testing::TestScene> scene_;
};

TEST_F(ResumeTest, PathModeWithTheGuideLearningAcrossStops) {
    Load("clutter:bricks=2", "test_clutter.toml", [](SceneConfig* c) {
        c->camera.width = 40;
        c->camera.height = 30;
        c->render.spp = 11;
        c->render.path_guiding = true;
    });
    ASSERT_TRUE(scene_->scene.settings.path_guiding);
    // Stops before and after guide updates (passes 1, 2, 4, 8).
    ExpectResumedEqualsUninterrupted({1, 2, 4}, 11);
}

TEST_F(ResumeTest, PhotonModeWithRadiiDensitiesAndPhotonGuides) {
    Load("caustic", "test_caustic.toml", [](SceneConfig* c) {
        c->camera.width = 40;
        c->camera.height = 30;
        c->render.iterations = 6;
        c->render.photons_per_iteration = 20000;
    });
    ExpectResumedEqualsUninterrupted({2, 1}, 6);
}

TEST_F(ResumeTest, PhotonModeWithFinalGatherItsGuideAndTheLearnedWindows) {
    // The room lit by the sky through a window in its roof: what the gather guide and the sky's
    // windows learn from the photons carries over a stop.
    LoadMesh(testing::RoomWithRoofWindow(), {"floor", "wall", "window"},
             testing::RoomWithRoofWindowScene() + R"(
[render]
mode = "photon"
final_gather = true
photon_target = "portals"
sky_sampling = "portals"
iterations = 5
photons_per_iteration = 20000
max_depth = 4
)");
    ExpectResumedEqualsUninterrupted({2, 1}, 5);
}

TEST_F(ResumeTest, ACheckpointOfAnotherSizeIsRefused) {
    Load("clutter", "test_clutter.toml", [](SceneConfig* c) {
        c->camera.width = 16;
        c->camera.height = 12;
        c->render.spp = 2;
    });
    SessionOptions o = Options("small.ckpt");
    o.stop_after = 1;
    Render(o);
    auto read = ReadCheckpoint(o.checkpoint_path);
    ASSERT_TRUE(read.ok());
    Load("clutter", "test_clutter.toml", [](SceneConfig* c) {
        c->camera.width = 20;
        c->camera.height = 12;
        c->render.spp = 2;
    });
    SessionOptions resumed = Options("small.ckpt");
    resumed.resume = &*read;
    resumed.resume_name = "small.ckpt";
    testing::RunOptions run;
    run.session = &resumed;
    const Status s = scene_->Run(run).status;
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), StatusCode::kDataLoss);
    EXPECT_NE(s.message().find("a film of 16x12, this render's is 20x12"), std::string::npos)
        << s.message();
}

}  // namespace
}  // namespace nave::render
