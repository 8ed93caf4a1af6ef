// The culling parameter table: order, defaults, parsing and its errors.
#include "culling/core/errors.hpp"
#include "culling/core/params.hpp"

#include <gtest/gtest.h>

using namespace lc;

TEST(Params, TableOrderAndDefaultsMatchTheStructs) {
    const auto& t = cullParams();
    std::vector<std::string> names;
    for (const auto& p : t) names.push_back(p.name);
    EXPECT_EQ(names, (std::vector<std::string>{"algorithm", "test", "cells", "slicing", "skip-empty", "spot-test", "bins",
                                               "proxy-level", "proxy-segments", "proxy-cone-angle", "proxy-overfit",
                                               "conservative", "proxy-depth", "tile", "width", "height", "cap", "max-lights",
                                               "max-entries", "overflow-policy", "limit-keep"}));
    // The table's defaults are the structs' defaults.
    const CullSettings s;
    const Camera cam;
    for (const auto& p : t) {
        EXPECT_EQ(getParam(s, cam, p.name), p.defaultValue) << p.name;
        EXPECT_FALSE(p.help.empty()) << p.name;
        EXPECT_FALSE(p.label.empty()) << p.name;
    }
    EXPECT_EQ(cullParam("algorithm").choices,
              (std::vector<std::string>{"all", "naive", "minmax", "halfz", "2.5d", "clustered", "fptl", "zbin", "raster"}));
    EXPECT_EQ(cullParam("test").choices, (std::vector<std::string>{"planes", "planes+aabb", "exact"}));
    EXPECT_EQ(cullParam("cells").minValue, 1);
    EXPECT_EQ(cullParam("cells").maxValue, 32);
    EXPECT_EQ(cullParam("tile").maxValue, 256);
    EXPECT_EQ(cullParam("width").maxValue, 16384);
    EXPECT_EQ(cullParam("skip-empty").type, ParamType::Bool);
    EXPECT_EQ(cullParam("bins").minValue, 1);
    EXPECT_EQ(cullParam("bins").maxValue, 16384);
    EXPECT_THROW(cullParam("colour"), SettingsError);
    // raster's overfit: a number in 0.5..4, or auto (0: the enclosing factor).
    EXPECT_EQ(cullParam("proxy-overfit").type, ParamType::Real);
    {
        CullSettings r;
        Camera c;
        setParam(r, c, "proxy-overfit", "1.25");
        EXPECT_EQ(r.proxyOverfit, 1.25);
        EXPECT_EQ(getParam(r, c, "proxy-overfit"), "1.25");
        setParam(r, c, "proxy-overfit", "auto");
        EXPECT_EQ(r.proxyOverfit, 0.0);
        EXPECT_EQ(getParam(r, c, "proxy-overfit"), "auto");
        for (const char* bad : {"0.4", "4.5", "1,2", "", "nan", "inf", "autox"}) {
            try {
                setParam(r, c, "proxy-overfit", bad);
                ADD_FAILURE() << "accepted '" << bad << "'";
            } catch (const SettingsError& e) {
                EXPECT_NE(std::string(e.what()).find("must be a number in 0.5..4 or auto"), std::string::npos) << e.what();
            }
        }
        r.proxyOverfit = 7;
        EXPECT_NE(r.validate().find("proxy-overfit"), std::string::npos);
    }
    // The engine limits: off by default, on their own toolbar row.
    for (const char* n : {"cap", "max-lights", "max-entries", "overflow-policy", "limit-keep"})
        EXPECT_EQ(cullParam(n).group, "limits") << n;
    EXPECT_EQ(cullParam("algorithm").group, "");
    EXPECT_FALSE(s.hasLimits());
    EXPECT_EQ(cullParam("overflow-policy").choices, (std::vector<std::string>{"index", "nearest", "all-lights"}));
    EXPECT_EQ(cullParam("limit-keep").choices, (std::vector<std::string>{"index", "nearest"}));
    CullSettings capped;
    Camera c;
    setParam(capped, c, "cap", "63");
    setParam(capped, c, "overflow-policy", "all-lights");
    EXPECT_EQ(capped.cap, 63u);
    EXPECT_EQ(capped.overflow, OverflowPolicy::AllLights);
    EXPECT_TRUE(capped.hasLimits());
    EXPECT_THROW(setParam(capped, c, "cap", "-1"), SettingsError);
    EXPECT_THROW(setParam(capped, c, "limit-keep", "all-lights"), SettingsError);
}

TEST(Params, SetAndGetRoundTripEveryValue) {
    CullSettings s;
    Camera cam;
    for (const auto& p : cullParams()) {
        std::vector<std::string> values = p.choices;
        if (p.type == ParamType::Int)
            values = {std::to_string(p.minValue), std::to_string(p.maxValue), std::to_string((p.minValue + p.maxValue) / 2)};
        if (p.type == ParamType::Bool) values = {"false", "true"};
        if (p.type == ParamType::Real) values = {"auto", "0.5", "4", "1.0705"};
        for (const auto& v : values) {
            setParam(s, cam, p.name, v);
            EXPECT_EQ(getParam(s, cam, p.name), v) << p.name;
        }
    }
    setParam(s, cam, "algorithm", "clustered");
    setParam(s, cam, "cells", "7");
    setParam(s, cam, "tile", "32");
    setParam(s, cam, "width", "1366");
    setParam(s, cam, "skip-empty", "0");
    EXPECT_EQ(s.algorithm, Algorithm::Clustered);
    EXPECT_EQ(s.cells, 7u);
    EXPECT_EQ(cam.tileSize, 32u);
    EXPECT_EQ(cam.width, 1366u);
    EXPECT_FALSE(s.skipEmpty);
    EXPECT_EQ(s.validate(), "");
}

TEST(Params, BadValuesNameTheParameterAndTheValue) {
    CullSettings s;
    Camera cam;
    const CullSettings before = s;
    auto expectError = [&](const std::string& name, const std::string& value, const std::string& needle) {
        try {
            setParam(s, cam, name, value);
            ADD_FAILURE() << name << "=" << value << " accepted";
        } catch (const SettingsError& e) {
            EXPECT_EQ(e.field(), name);
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expectError("cells", "40", "must be an integer in 1..32, got '40'");
    expectError("cells", "0", "got '0'");
    expectError("cells", "3x", "got '3x'");
    expectError("cells", "", "got ''");
    expectError("cells", "99999999999999999999", "1..32");
    expectError("tile", "257", "1..256");
    expectError("width", "-5", "1..16384");
    expectError("height", "16385", "1..16384");
    expectError("algorithm", "tiled", "got 'tiled'");
    expectError("test", "sphere", "planes, planes+aabb, exact");
    expectError("slicing", "exp", "got 'exp'");
    expectError("skip-empty", "maybe", "true or false");
    EXPECT_THROW(setParam(s, cam, "bogus", "1"), SettingsError);
    // Nothing was changed by the failed calls.
    EXPECT_EQ(s.cells, before.cells);
    EXPECT_EQ(s.algorithm, before.algorithm);
    EXPECT_EQ(cam.tileSize, Camera{}.tileSize);
}

TEST(Params, AlgorithmNamesAndSettingsValidate) {
    for (Algorithm a : {Algorithm::All, Algorithm::Naive, Algorithm::MinMax, Algorithm::HalfZ,
                        Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin})
        EXPECT_EQ(algorithmFromString(toString(a)), a);
    EXPECT_STREQ(toString(Algorithm::TwoPointFiveD), "2.5d");
    try {
        algorithmFromString("forward+");
        ADD_FAILURE();
    } catch (const SettingsError& e) {
        EXPECT_EQ(e.field(), "algorithm");
    }
    CullSettings s;
    EXPECT_EQ(s.validate(), "");
    s.cells = 0;
    EXPECT_NE(s.validate().find("cells"), std::string::npos);
    s.cells = 33;
    EXPECT_NE(s.validate().find("cells"), std::string::npos);
}
