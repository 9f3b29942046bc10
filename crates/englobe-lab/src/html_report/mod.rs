//! Reports as pages to look at: one self-contained HTML file each, for `englobe compare --report`
//! ([`compare`]) and `englobe experiment seed --report` ([`seed`]), built on what [`page`] gives
//! both (the page's head, pictures as data, the cost heatmaps on a shared scale, atomic writing).

pub mod compare;
pub mod page;
pub mod seed;

pub use compare::{render_pictures, report_page, write_report};
pub use page::{PREVIEW_WIDTH, ReportPictures};
pub use seed::{render_seed_pictures, seed_page, write_seed_report};
