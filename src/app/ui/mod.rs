//! The panes and bars of the workbench, one file each: each draws from the app's state and the
//! picked point's recording (`impl WorkbenchApp` blocks, so that `mod.rs` keeps the state and
//! its lifecycle).

mod dialogs;
mod frame;
mod lesson_capture;
mod light_structure;
mod menu;
mod picking;
mod plots;
mod scene;
mod settings;
mod stages_pane;
mod status;
mod viewport_image;
