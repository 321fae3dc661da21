//! What the user asks of the window through the panels, the flat pattern view or a
//! scripted session: a worker command, or something only the window can do.

use super::worker::Command;

/// What the window must do for the UI.
#[derive(Debug, Clone)]
pub enum Action {
    Send(Command),
    /// A file to pick, then read or write.
    File(FileDialog),
    Screenshot,
    /// Save the window, as F12 does, to this file (a scripted session's screenshot).
    SaveScreenshot(std::path::PathBuf),
    /// Keep the current fabric's picture and measures beside the live view.
    Pin,
}

/// What a file dialog is opened for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileDialog {
    OpenScene,
    SaveScene,
    OpenFabric,
    SaveFabric,
    ExportObj,
    ExportCsv,
    /// The cloth as it is now, as glTF binary (`crate::export`).
    ExportGltf,
}
