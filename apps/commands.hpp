#pragma once
// The scallop program's subcommands. Each one adds itself to the top-level CLI11 app and
// does its work from the subcommand's callback; every error it meets propagates out of
// CLI::App::parse to main(), the one place errors are caught and reported.

namespace CLI {
class App;
}  // namespace CLI

namespace scallop::cli {

/// `scallop hull`: the scallop hull of a chain and its tool-centre path, as JSON and/or SVG.
void addHullCommand(CLI::App& app);

/// `scallop orient`: the optimal slicing orientation of a surface, as JSON and/or SVG figures.
void addOrientCommand(CLI::App& app);

/// `scallop paths`: contour or raster tool paths of a surface, as JSON, G-code and/or SVG.
void addPathsCommand(CLI::App& app);

/// `scallop plan`: the main job, surface to G-code, report and figures in one folder.
void addPlanCommand(CLI::App& app);

/// `scallop verify`: simulate a G-code program's cut and compare it with the surface.
/// `exitStatus` receives the command's status (2: --fail-on-gouge and a gouge was found).
void addVerifyCommand(CLI::App& app, int& exitStatus);

}  // namespace scallop::cli
