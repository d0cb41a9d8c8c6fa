//! The table and CSV forms of the commands' documents (`chain::ops`), one
//! file per document; the JSON form is the document's own `Serialize`.

pub(crate) mod allocate;
pub(crate) mod circular;
pub(crate) mod compensate;
pub(crate) mod export;
pub(crate) mod identify;
pub(crate) mod map;
pub(crate) mod motion;
pub(crate) mod path;
pub(crate) mod plan;
pub(crate) mod positioning;
pub(crate) mod reliability;
pub(crate) mod report;
pub(crate) mod sensitivity;
pub(crate) mod sobol;
pub(crate) mod thermal;
