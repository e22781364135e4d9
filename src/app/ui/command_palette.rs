//! The command palette (Ctrl+P): every [`Command`] by name, filtered as one types, with its
//! shortcut; ↑/↓ choose, Enter or a click runs, Esc or Ctrl+P closes. It issues the same
//! commands as the keys and the menus.

use super::super::command::matching;
use super::super::*;

/// What is typed into the palette, and the highlighted match.
#[derive(Clone, Debug, Default)]
pub struct CommandPalette {
    query: String,
    selected: usize,
}

impl AppState {
    /// Draws the palette, if open, over the workbench; runs the chosen command.
    pub(in crate::app) fn palette_ui(&mut self, ctx: &egui::Context) {
        let Some(mut palette) = self.palette.take() else {
            return;
        };
        let (up, down, enter, escape) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::ArrowUp),
                i.key_pressed(egui::Key::ArrowDown),
                i.key_pressed(egui::Key::Enter),
                i.key_pressed(egui::Key::Escape),
            )
        });
        let found = matching(&palette.query);
        if down {
            palette.selected = (palette.selected + 1).min(found.len().saturating_sub(1));
        }
        if up {
            palette.selected = palette.selected.saturating_sub(1);
        }
        palette.selected = palette.selected.min(found.len().saturating_sub(1));
        let mut chosen = enter
            .then(|| found.get(palette.selected).cloned())
            .flatten();
        egui::Window::new("Commands")
            .title_bar(false)
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_TOP, egui::vec2(0.0, 60.0))
            .fixed_size(egui::vec2(420.0, 0.0))
            .show(ctx, |ui| {
                let edit = ui.add(
                    egui::TextEdit::singleline(&mut palette.query)
                        .hint_text("type to find a command")
                        .desired_width(f32::INFINITY),
                );
                edit.request_focus();
                if edit.changed() {
                    palette.selected = 0;
                }
                ui.separator();
                if found.is_empty() {
                    ui.weak("no command matches");
                }
                for (k, c) in found.iter().enumerate() {
                    ui.horizontal(|ui| {
                        let row = ui.selectable_label(k == palette.selected, c.label());
                        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                            ui.weak(c.shortcut_text());
                        });
                        if row.clicked() {
                            chosen = Some(c.clone());
                        }
                    });
                }
            });
        match chosen {
            Some(c) => self.run_command(c),
            None if escape => {}
            None => self.palette = Some(palette),
        }
    }
}
