return { name = 'x', --!
 links = { 
