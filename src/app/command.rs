//! Every action of the workbench that a key, a menu entry or a button can start, as one
//! [`Command`] (after rerun's `UICommand`): its name, its shortcut (defined here once, and
//! shown in the menus and in the help from here), and whether it waits while a text field has
//! the keyboard. `AppState::run_command` carries them out.

use super::figure_export::FigureView;
use super::layout::Preset;
use egui::{InputState, Key};

/// An action of the workbench. Most take no argument and are listed in [`Command::ALL`]; those
/// carrying one (which scene, which figure, which layout) are issued by the menu entries that
/// choose it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Command {
    Undo,
    Redo,
    /// Leave a maximised pane.
    Restore,
    NextStage,
    PreviousStage,
    AllStages,
    PlayStages,
    ResetCamera,
    SaveImage,
    SaveDump,
    Open,
    Screenshot,
    ToggleHelp,
    /// Every command by name, filtered as one types (rerun's and editors' palette).
    CommandPalette,
    /// The picked point shaded by Monte Carlo, beside the analytic numbers.
    MonteCarloCheck,
    /// A screenshot of the sphere view only.
    ScreenshotSphere,
    /// Save the scene as it is now, moved objects included.
    SaveScene,
    /// Every stage of the picked point as frames, a GIF and the lesson's text.
    ExportLesson,
    /// The command line that renders the view, to the clipboard.
    CopyCliCommand,
    /// Open the embedded scene of this name.
    OpenEmbedded(&'static str),
    /// Open a scene opened before (an embedded scene's name or a path).
    OpenRecent(String),
    /// Write the figure a view shows (asks where).
    ExportFigure(FigureView),
    /// Arrange the panes as a preset does.
    Layout(Preset),
}

impl Command {
    /// Every command without an argument, in the order a frame's key presses are carried out:
    /// what the keys, the help and the palette go through. A command carrying an argument has
    /// no shortcut and is issued from its menu.
    pub const ALL: [Command; 19] = [
        Command::Undo,
        Command::Redo,
        Command::Restore,
        Command::NextStage,
        Command::PreviousStage,
        Command::AllStages,
        Command::PlayStages,
        Command::ResetCamera,
        Command::SaveImage,
        Command::SaveDump,
        Command::Open,
        Command::Screenshot,
        Command::ToggleHelp,
        Command::CommandPalette,
        Command::MonteCarloCheck,
        Command::ScreenshotSphere,
        Command::SaveScene,
        Command::ExportLesson,
        Command::CopyCliCommand,
    ];

    /// What the command does, as the help and the menus say it.
    pub(crate) fn label(&self) -> &'static str {
        match self {
            Command::Undo => "undo the last move",
            Command::Redo => "redo",
            Command::Restore => "leave a maximised pane",
            Command::NextStage => "next stage",
            Command::PreviousStage => "previous stage",
            Command::AllStages => "show all stages",
            Command::PlayStages => "play / pause the stages",
            Command::ResetCamera => "reset the camera",
            Command::SaveImage => "save the rendered image",
            Command::SaveDump => "save the debug dump of the picked point",
            Command::Open => "open a scene, dump, bench report or reference",
            Command::Screenshot => "screenshot of the window",
            Command::ToggleHelp => "this help",
            Command::CommandPalette => "find a command by name",
            Command::MonteCarloCheck => "check the picked point by Monte Carlo (65,536 samples)",
            Command::ScreenshotSphere => "screenshot of the sphere view",
            Command::SaveScene => "save the scene as it is now (TOML, with its OBJ and MTL)",
            Command::ExportLesson => {
                "export the lesson of the picked point (frames, an animated GIF, its text)"
            }
            Command::CopyCliCommand => "copy the command line that renders this view",
            Command::OpenEmbedded(_) => "open an embedded scene",
            Command::OpenRecent(_) => "open a recent scene",
            Command::ExportFigure(_) => "export a view's figure (SVG, PDF or PNG)",
            Command::Layout(_) => "arrange the panes by a preset",
        }
    }

    /// The key chords that run the command, the one description its text and its test
    /// read; none for a command issued from its button, a menu or the palette.
    pub(crate) fn shortcuts(&self) -> &'static [Chord] {
        match self {
            Command::Undo => const { &[Chord::ctrl(Key::Z)] },
            Command::Redo => const { &[Chord::ctrl(Key::Y), Chord::ctrl_shift(Key::Z)] },
            Command::Restore => const { &[Chord::key(Key::Escape)] },
            Command::NextStage => const { &[Chord::key(Key::ArrowRight), Chord::key(Key::Space)] },
            Command::PreviousStage => const { &[Chord::key(Key::ArrowLeft)] },
            Command::AllStages => const { &[Chord::key(Key::Home)] },
            Command::PlayStages => const { &[Chord::key(Key::P)] },
            Command::ResetCamera => const { &[Chord::key(Key::R)] },
            Command::SaveImage => const { &[Chord::ctrl(Key::S)] },
            Command::SaveDump => const { &[Chord::ctrl(Key::D)] },
            Command::Open => const { &[Chord::ctrl(Key::O)] },
            Command::Screenshot => const { &[Chord::key(Key::F12)] },
            Command::ToggleHelp => const { &[Chord::key(Key::F1)] },
            Command::CommandPalette => const { &[Chord::ctrl(Key::P)] },
            Command::MonteCarloCheck
            | Command::ScreenshotSphere
            | Command::SaveScene
            | Command::ExportLesson
            | Command::CopyCliCommand
            | Command::OpenEmbedded(_)
            | Command::OpenRecent(_)
            | Command::ExportFigure(_)
            | Command::Layout(_) => &[],
        }
    }

    /// The shortcut as written in the help and the menus ("Ctrl+Y / Ctrl+Shift+Z"); empty for
    /// a command without one.
    pub(crate) fn shortcut_text(&self) -> String {
        let chords: Vec<String> = self.shortcuts().iter().map(|c| c.to_string()).collect();
        chords.join(" / ")
    }

    /// The shortcut as the help lists it: "—" for a command without one (its button, a menu
    /// or the palette issues it).
    pub(crate) fn help_keys(&self) -> String {
        match self.shortcut_text() {
            keys if keys.is_empty() => "—".to_string(),
            keys => keys,
        }
    }

    /// A menu entry's text: `name (shortcut)`, or the name alone without a shortcut.
    pub(crate) fn menu_text(&self, name: &str) -> String {
        match self.shortcut_text() {
            keys if keys.is_empty() => name.to_string(),
            keys => format!("{name} ({keys})"),
        }
    }

    /// Whether one of the command's chords was pressed this frame.
    pub(crate) fn pressed(&self, i: &InputState) -> bool {
        self.shortcuts().iter().any(|c| c.pressed(i))
    }

    /// Whether the shortcut acts while a text field has the keyboard (a plain key such as
    /// Space or R belongs to the text field then).
    pub(crate) fn while_typing(&self) -> bool {
        !matches!(
            self,
            Command::Undo
                | Command::Redo
                | Command::NextStage
                | Command::PreviousStage
                | Command::AllStages
                | Command::PlayStages
                | Command::ResetCamera
        )
    }
}

/// A key with exactly the modifiers it needs (Ctrl is the command key: ⌘ on macOS), so that
/// Ctrl+P and P are different shortcuts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Chord {
    ctrl: bool,
    shift: bool,
    key: Key,
}

impl Chord {
    const fn key(key: Key) -> Chord {
        Chord {
            ctrl: false,
            shift: false,
            key,
        }
    }

    const fn ctrl(key: Key) -> Chord {
        Chord {
            ctrl: true,
            shift: false,
            key,
        }
    }

    const fn ctrl_shift(key: Key) -> Chord {
        Chord {
            ctrl: true,
            shift: true,
            key,
        }
    }

    fn pressed(self, i: &InputState) -> bool {
        i.modifiers.command == self.ctrl
            && i.modifiers.shift == self.shift
            && i.key_pressed(self.key)
    }
}

impl std::fmt::Display for Chord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.ctrl {
            f.write_str("Ctrl+")?;
        }
        if self.shift {
            f.write_str("Shift+")?;
        }
        f.write_str(match self.key {
            Key::Escape => "Esc",
            Key::ArrowRight => "Right",
            Key::ArrowLeft => "Left",
            key => key.name(),
        })
    }
}

/// The commands whose label contains every word of `query` (case-insensitive), in
/// [`Command::ALL`]'s order; all of them for an empty query. The palette lists these.
pub(crate) fn matching(query: &str) -> Vec<Command> {
    let words: Vec<String> = query.split_whitespace().map(str::to_lowercase).collect();
    Command::ALL
        .into_iter()
        .filter(|c| c != &Command::CommandPalette)
        .filter(|c| {
            let label = c.label().to_lowercase();
            words.iter().all(|w| label.contains(w.as_str()))
        })
        .collect()
}

/// The help's rows: every command's shortcut and what it does, then the mouse.
pub(crate) fn help_rows() -> impl Iterator<Item = (String, &'static str)> {
    const MOUSE: [(&str, &str); 2] = [
        ("drag", "orbit (left), pan (right or middle); scroll: zoom"),
        ("click", "pick a pixel"),
    ];
    Command::ALL
        .into_iter()
        .map(|c| (c.help_keys(), c.label()))
        .chain(MOUSE.map(|(k, what)| (k.to_string(), what)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each shortcut fires its own command and no other (a shared key would run two).
    #[test]
    fn each_shortcut_runs_exactly_its_command() {
        let cases: [(Key, egui::Modifiers, Command); 15] = [
            (Key::Z, egui::Modifiers::COMMAND, Command::Undo),
            (Key::Y, egui::Modifiers::COMMAND, Command::Redo),
            (
                Key::Z,
                egui::Modifiers::COMMAND.plus(egui::Modifiers::SHIFT),
                Command::Redo,
            ),
            (Key::Escape, egui::Modifiers::NONE, Command::Restore),
            (Key::ArrowRight, egui::Modifiers::NONE, Command::NextStage),
            (Key::Space, egui::Modifiers::NONE, Command::NextStage),
            (
                Key::ArrowLeft,
                egui::Modifiers::NONE,
                Command::PreviousStage,
            ),
            (Key::Home, egui::Modifiers::NONE, Command::AllStages),
            (Key::P, egui::Modifiers::NONE, Command::PlayStages),
            (Key::R, egui::Modifiers::NONE, Command::ResetCamera),
            (Key::S, egui::Modifiers::COMMAND, Command::SaveImage),
            (Key::D, egui::Modifiers::COMMAND, Command::SaveDump),
            (Key::O, egui::Modifiers::COMMAND, Command::Open),
            (Key::F12, egui::Modifiers::NONE, Command::Screenshot),
            (Key::P, egui::Modifiers::COMMAND, Command::CommandPalette),
        ];
        for (key, modifiers, want) in cases {
            let ctx = egui::Context::default();
            let mut input = egui::RawInput::default();
            input.events.push(egui::Event::ModifiersChanged(modifiers));
            input.events.push(egui::Event::Key {
                key,
                physical_key: None,
                pressed: true,
                repeat: false,
                modifiers,
            });
            let mut fired = Vec::new();
            let mut out = ctx.run_ui(input, |ui| {
                fired = ui.input(|i| {
                    Command::ALL
                        .into_iter()
                        .filter(|c| c.pressed(i))
                        .collect::<Vec<Command>>()
                });
            });
            out.textures_delta.clear();
            assert_eq!(fired, vec![want], "{key:?} with {modifiers:?}");
        }
        // The palette finds a command by any words of its label.
        assert_eq!(matching("SAVE dump"), vec![Command::SaveDump]);
        assert_eq!(matching("save scene"), vec![Command::SaveScene]);
        assert_eq!(matching("stage").len(), 4);
        assert_eq!(matching("").len(), Command::ALL.len() - 1);
        assert!(matching("no such thing").is_empty());
        // Shortcuts read as the keys are labelled.
        assert_eq!(Command::Redo.shortcut_text(), "Ctrl+Y / Ctrl+Shift+Z");
        assert_eq!(Command::NextStage.shortcut_text(), "Right / Space");
        assert_eq!(Command::Restore.menu_text("restore"), "restore (Esc)");
        assert_eq!(Command::ToggleHelp.help_keys(), "F1");
        assert_eq!(Command::SaveScene.help_keys(), "—");
        // Every command is in the help, with its shortcut (or "—").
        let rows: Vec<_> = help_rows().collect();
        for c in Command::ALL {
            assert!(rows.contains(&(c.help_keys(), c.label())), "{c:?}");
        }
    }
}
