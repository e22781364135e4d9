//! The unit sphere at the picked point, as two panes: the sphere in 3-D ([`SpherePane`]) and
//! the hemisphere seen from above ([`HemispherePane`]), both drawn from the figures of
//! `views::sphere` with the view state they share ([`SphereView`], a setting kept between
//! sessions).

mod hemisphere_pane;
mod sphere_pane;
mod sphere_view;

pub use hemisphere_pane::HemispherePane;
pub use sphere_pane::SpherePane;
pub use sphere_view::{SphereFigure, SphereView};
