//! Whether a worker's lease still holds the running job it writes for, checked inside the
//! write's transaction. Imports the store's backend and database handle; the claims, the
//! checkpoints and the frames import it.

use super::backend::Backend;
use super::database::{Result, WriteTx};
use uuid::Uuid;

/// Whether `lease` still holds the running job `id`: `Some(cancel_requested)` if it does.
/// The row stays locked to the end of the transaction on PostgreSQL, so no cancel or reaper
/// can change it between this check and the write that follows.
pub(super) async fn holds(
    backend: &Backend,
    tx: &mut WriteTx,
    id: Uuid,
    lease: Uuid,
) -> Result<Option<bool>> {
    let sql = format!(
        "SELECT cancel_requested FROM jobs WHERE id = $1 AND lease = $2 AND status = 'running'{}",
        backend.for_update()
    );
    let row: Option<(i64,)> = sqlx::query_as(&sql)
        .bind(id.to_string())
        .bind(lease.to_string())
        .fetch_optional(&mut **tx)
        .await?;
    Ok(row.map(|(c,)| c != 0))
}
