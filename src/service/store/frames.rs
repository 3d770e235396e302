//! The frames of a job's time series (`output.frames`): each stored under the claim's lease as
//! the run reaches it (a run that starts over writes them again), read one at a time, and gone
//! with the job or when its run fails or is cancelled.

use super::worker::holds;
use super::{Result, Store};
use crate::export::series::FrameTime;
use sqlx::Any;
use uuid::Uuid;

/// One frame as the worker stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredFrame {
    pub at: FrameTime,
    pub particles: usize,
    /// The stored form (`export::series::encode`).
    pub data: Vec<u8>,
}

impl Store {
    /// Stores `frame` as job `id`'s (replacing one of the same index) while `lease` holds the
    /// job; false when the lease was lost: nothing is written.
    pub async fn save_frame(&self, id: Uuid, lease: Uuid, frame: &StoredFrame) -> Result<bool> {
        let mut tx = self.write().await?;
        if holds(&self.backend, &mut tx, id, lease).await?.is_none() {
            return Ok(false);
        }
        sqlx::query(
            "INSERT INTO frames (job_id, k, travel_mm, time_ms, particles, data) \
             VALUES ($1, $2, $3, $4, $5, $6) ON CONFLICT (job_id, k) DO UPDATE SET \
             travel_mm = excluded.travel_mm, time_ms = excluded.time_ms, \
             particles = excluded.particles, data = excluded.data",
        )
        .bind(id.to_string())
        .bind(frame.at.index as i64)
        .bind(frame.at.travel_mm)
        .bind(frame.at.time_ms)
        .bind(frame.particles as i64)
        .bind(frame.data.as_slice())
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(true)
    }

    /// Where each of job `id`'s stored frames stands, in order (none: an empty list).
    pub async fn frame_times(&self, id: Uuid) -> Result<Vec<FrameTime>> {
        let rows: Vec<(i64, f64, f64)> =
            sqlx::query_as("SELECT k, travel_mm, time_ms FROM frames WHERE job_id = $1 ORDER BY k")
                .bind(id.to_string())
                .fetch_all(&self.pool)
                .await?;
        Ok(rows
            .into_iter()
            .map(|(k, travel_mm, time_ms)| FrameTime {
                index: k.clamp(0, u32::MAX as i64) as u32,
                travel_mm,
                time_ms,
            })
            .collect())
    }

    /// Frame `k` of job `id`, if stored.
    pub async fn frame(&self, id: Uuid, k: u32) -> Result<Option<StoredFrame>> {
        let row: Option<(f64, f64, i64, Vec<u8>)> = sqlx::query_as(
            "SELECT travel_mm, time_ms, particles, data FROM frames WHERE job_id = $1 AND k = $2",
        )
        .bind(id.to_string())
        .bind(k as i64)
        .fetch_optional(&self.pool)
        .await?;
        Ok(
            row.map(|(travel_mm, time_ms, particles, data)| StoredFrame {
                at: FrameTime {
                    index: k,
                    travel_mm,
                    time_ms,
                },
                particles: particles.max(0) as usize,
                data,
            }),
        )
    }
}

/// Deletes job `job`'s frames: its run failed or was cancelled.
pub(super) async fn forget(tx: &mut sqlx::Transaction<'static, Any>, job: &str) -> Result<()> {
    sqlx::query("DELETE FROM frames WHERE job_id = $1")
        .bind(job)
        .execute(&mut **tx)
        .await?;
    Ok(())
}
