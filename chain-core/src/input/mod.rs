//! Stage 1, machine input and validation: the located YAML tree ([`yaml`]),
//! the `machine!` inline syntax ([`inline`]), offset and statistics
//! expressions ([`expr`]), every rule of the machine file ([`load`]) with its
//! located errors ([`diagnostic`]), the validated [`model`], the settings
//! files of `chain motion` ([`settings`]) and the values files of a built
//! machine ([`values`]).

pub mod bounded;
pub mod diagnostic;
pub mod expr;
pub mod inline;
pub mod load;
pub mod model;
pub mod settings;
pub mod tabular;
pub mod values;
pub mod yaml;
