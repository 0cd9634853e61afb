//! How the solvers use the machine: fork–join on Rayon's pool ([`fork_join`]), work on idle
//! core time ([`idle_task`]), working matrices kept between solves ([`scratch`]) and the CPU's
//! vector instructions ([`cpu`]). Nothing here knows about pencils or modes.

pub(crate) mod cpu;
pub(crate) mod fork_join;
pub(crate) mod idle_task;
pub(crate) mod scratch;
