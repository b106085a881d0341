//! The answering end of a query: decode the request, reply with a message or with the
//! structured error.

use roam_proto::{decode, encode, excerpt, ErrorCode, ErrorReply, Message};
use zenoh::query::Query;

/// Decodes a query's payload as `T`, refusing payloads above `max_bytes` by name.
pub fn decode_request<T: Message>(query: &Query, max_bytes: usize) -> Result<T, ErrorReply> {
    let Some(payload) = query.payload() else {
        return Err(ErrorReply::new(
            ErrorCode::Malformed,
            format!("this query needs a '{}' message as its payload", T::KIND),
        ));
    };
    if payload.len() > max_bytes {
        return Err(ErrorReply::limit(
            "max_request_bytes",
            max_bytes as u64,
            payload.len() as u64,
            format!(
                "the request is {} bytes; send at most {max_bytes} (split the update or raise max_request_bytes)",
                payload.len()
            ),
        ));
    }
    decode(&payload.to_bytes()).map_err(|e| e.to_reply())
}

/// Replies with a message on the query's own key expression.
pub async fn send<T: Message>(query: &Query, message: &T) {
    let bytes = encode(message);
    if let Err(e) = query.reply(query.key_expr().clone(), bytes).await {
        tracing::warn!(key = %excerpt(query.key_expr().as_str()), "reply failed: {e}");
    }
}

/// Replies with a structured error.
pub async fn send_error(query: &Query, error: &ErrorReply) {
    tracing::debug!(key = %excerpt(query.key_expr().as_str()), %error, "refusing query");
    if let Err(e) = query.reply_err(encode(error)).await {
        tracing::warn!(key = %excerpt(query.key_expr().as_str()), "error reply failed: {e}");
    }
}

/// Replies with the result of a handler.
pub async fn send_result<T: Message>(query: &Query, result: Result<T, ErrorReply>) {
    match result {
        Ok(message) => send(query, &message).await,
        Err(error) => send_error(query, &error).await,
    }
}

/// Refuses a query because the service is stopping.
pub async fn refuse_stopping(query: &Query, service: &str) {
    let error = ErrorReply::new(
        ErrorCode::Unavailable,
        format!("{service} is shutting down; retry against another instance or after its restart"),
    );
    send_error(query, &error).await;
}
