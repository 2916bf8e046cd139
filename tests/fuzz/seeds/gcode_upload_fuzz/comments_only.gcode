; nothing here
(block comment)

   
