//! The workbench's menu bar (its entries issue `Command`s).

use super::super::*;

impl AppState {
    pub(in crate::app) fn menu_ui(&mut self, ui: &mut Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button(Command::Open.menu_text("Open…")).clicked() {
                    self.run_command(Command::Open);
                }
                ui.menu_button("Embedded scenes", |ui| {
                    for name in scene_file::embedded_scene_names() {
                        if ui.button(*name).clicked() {
                            self.run_command(Command::OpenEmbedded(name));
                        }
                    }
                });
                ui.menu_button("Recent", |ui| {
                    for r in self.settings.recent.clone() {
                        if ui.button(&r).clicked() {
                            self.run_command(Command::OpenRecent(r));
                        }
                    }
                });
                ui.separator();
                if ui
                    .button(Command::SaveImage.menu_text("Save image…"))
                    .clicked()
                {
                    self.run_command(Command::SaveImage);
                }
                if ui
                    .button(Command::SaveDump.menu_text("Save debug dump…"))
                    .clicked()
                {
                    self.run_command(Command::SaveDump);
                }
                if ui
                    .button(Command::Screenshot.menu_text("Screenshot of the window…"))
                    .clicked()
                {
                    self.run_command(Command::Screenshot);
                }
                if ui
                    .button(Command::ScreenshotSphere.menu_text("Screenshot of the sphere view…"))
                    .clicked()
                {
                    self.run_command(Command::ScreenshotSphere);
                }
                if ui
                    .button(Command::CopyCliCommand.menu_text("Copy CLI command"))
                    .clicked()
                {
                    self.run_command(Command::CopyCliCommand);
                }
            });
            ui.menu_button("Export", |ui| {
                ui.menu_button("Figure", |ui| {
                    for v in figure_export::FigureView::ALL {
                        if ui.button(format!("{}…", v.title())).clicked() {
                            self.run_command(Command::ExportFigure(v));
                            ui.close();
                        }
                    }
                    ui.separator();
                    ui.checkbox(
                        &mut self.figure_print,
                        "print style (light, greyscale-safe)",
                    );
                    ui.label(RichText::new("SVG, PDF or PNG by the file's extension").small());
                });
                ui.label(RichText::new("the rendered image and the debug dump: File").small());
            });
            ui.menu_button("View", |ui| {
                if ui.checkbox(&mut self.settings.dark, "dark theme").changed() {
                    self.apply_theme(ui.ctx());
                }
                ui.separator();
                ui.menu_button("Layout", |ui| {
                    for p in Preset::ALL {
                        if ui
                            .selectable_label(self.settings.preset == p, p.name())
                            .clicked()
                        {
                            self.run_command(Command::Layout(p));
                        }
                    }
                });
                ui.menu_button("Panes", |ui| {
                    for p in Pane::ALL {
                        let mut shown = layout::find(&self.tree, p)
                            .is_some_and(|id| self.tree.tiles.is_visible(id));
                        if ui.checkbox(&mut shown, p.title()).changed() {
                            if shown {
                                layout::reveal(&mut self.tree, p);
                            } else if let Some(id) = layout::find(&self.tree, p) {
                                self.tree.tiles.set_visible(id, false);
                            }
                        }
                    }
                });
                ui.checkbox(&mut self.show_help, Command::ToggleHelp.menu_text("help"));
                if ui
                    .button(Command::CommandPalette.menu_text("Commands…"))
                    .clicked()
                {
                    self.run_command(Command::CommandPalette);
                    ui.close();
                }
            });
        });
    }
}
